// shade.frag.glsl — deferred shading, one fragment per pixel: render_cpu.cpp's shade() and
// lit(), reading what frusta.frag.glsl wrote, through the model's functions in shading.glsl
// (the file before this one; the model is stated in core/light/shading.h). The ground plane and
// the sky are found here analytically, as the CPU does per ray.
//
// Sun visibility comes from a shadow map rendered by the same ray-casting shaders
// (SHADOW_PASS), orthographic along the sun direction of this pass: the CPU's shadow ray
// toward the same direction, resolved to the map's texels (bilinear 2x2 comparison). The
// receiver is moved along its geometric normal by u_normal_offset_m (a couple of texels)
// before the lookup, so a lit surface never shadows itself; a relief-mapped plant's by at
// least one pixel footprint, as the CPU starts its shadow rays (render_cpu.h).
//
// Albedo: g_albedo where the geometry pass decided it (a = 1: a bark texture, already
// linear), else the material table, material 0 replaced by the plant's bark colour.
//
// FOG (a scene with fog; fog.glsl comes before this file): as render_cpu.cpp's lit() and
// shade(), the sunlight reaching a surface is E_sun·T_sun(p) (toward the sun's centre), and
// what the pixel sees, surface or sky, arrives multiplied by T(0, t_end); the fog's own
// light is added by the fog pass (fog.frag.glsl).

layout(binding = G_NORMAL_DISTANCE_UNIT) uniform sampler2D g_normal_distance;
layout(binding = G_GEOMETRIC_U_UNIT) uniform sampler2D g_geometric_u;
layout(binding = G_IDS_UNIT) uniform usampler2D g_ids;
layout(binding = G_ALBEDO_UNIT) uniform sampler2D g_albedo;
#ifdef SUN
layout(binding = SHADOW_MAP_UNIT) uniform sampler2DShadow shadow_map;
#endif

// plant_maps (bark.glsl, the file before this one): which plants are relief-mapped.
// Per plant: bark albedo (rgb) and w = 1 where it replaces material 0 (Bark::albedo_rgb).
layout(std430, binding = PLANT_BARK_BINDING) readonly buffer PlantBark { vec4 plant_bark[]; };

uniform vec3 u_material_albedo[MAX_MATERIALS];  // material_look (scene.h): the scene's table over materials.h's
uniform float u_material_specular[MAX_MATERIALS];  // the Blinn–Phong lobe's weight per material
uniform int u_material_count;
// A material past the table (index ≥ u_material_count): default_material_albedo's last
// colour, specular weight 1 (material_look: the table cannot describe it).
uniform vec3 u_material_albedo_beyond;

uniform vec3 u_right;        // camera frame, as frusta_common.glsl
uniform vec3 u_up;
uniform vec3 u_forward;
uniform vec2 u_half_size;
uniform vec2 u_image_size;
uniform vec2 u_jitter;
uniform float u_eye_above_ground;  // eye.y − ground.height
uniform vec3 u_sky;                // L_sky
uniform vec3 u_ground_albedo;
#ifdef SUN
uniform vec3 u_sun_dir;            // unit, toward the sun (this pass's sample of the disc)
uniform vec3 u_sun_radiance;       // E_sun
uniform vec3 u_eye_rel_light;      // eye − the shadow map's centre c
uniform vec3 u_light_e0;           // the map's frame (frusta_common.glsl)
uniform vec3 u_light_e1;
uniform vec4 u_light_rect;
uniform vec2 u_light_depth;
uniform float u_normal_offset_m;   // receiver offset along its geometric normal
uniform float u_depth_bias;        // in map depth units (0..1)
uniform float u_pixel_step_rad;    // |∂direction/∂y|: a pixel footprint per unit of t
#endif
#ifdef FOG
uniform vec4 u_fog_medium;         // sigma_s, sigma_a, g, height_falloff (fog.frag.glsl's)
uniform float u_fog_top;           // top − ground.height (+inf: none)
uniform vec3 u_fog_sun_dir;        // unit, toward the sun's centre (T_sun)

FogMedium shade_fog_medium() {
  return fog_medium(u_fog_medium.x, u_fog_medium.y, u_fog_medium.z, u_fog_medium.w, 0.0, u_fog_top);
}
#endif

layout(location = 0) out vec4 colour;

vec3 camera_ray_direction(vec2 pixel) {
  float sx = (2.0 * pixel.x / u_image_size.x - 1.0) * u_half_size.x;
  float sy = (1.0 - 2.0 * pixel.y / u_image_size.y) * u_half_size.y;
  return u_forward + sx * u_right + sy * u_up;
}

#ifdef SUN
// Sun visibility of a point p (relative to the map's centre) with geometric normal n_geometric.
float sun_visibility(vec3 p, vec3 n_geometric, float offset_m) {
  vec3 q = p + max(u_normal_offset_m, offset_m) * n_geometric;
  vec2 uv = (vec2(dot(q, u_light_e0), dot(q, u_light_e1)) - u_light_rect.xy) / u_light_rect.zw;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;  // no caster there
  // Beyond the farthest caster the reference is clamped to the empty map's 1: still lit
  // where nothing is in the way, shadowed behind every caster.
  float depth = min((-dot(q, u_sun_dir) - u_light_depth.x) / u_light_depth.y - u_depth_bias, 1.0);
  return texture(shadow_map, vec3(uv, depth));
}
#endif

// The model at a surface point, the shadow map looked up only where the sun faces it.
vec3 lit(vec3 albedo, vec3 n, vec3 n_geometric, vec3 p_rel_eye, vec3 view, float specular, float shadow_offset_m) {
#ifdef SUN
  vec3 l = u_sun_dir;
  float cos_sun = sun_cosine(n, n_geometric, l);
#ifdef FOG
  // Through fog the sunlight arrives attenuated by T_sun; where none arrives nothing is looked up.
  float sun_transmittance =
      cos_sun > 0.0 ? fog_sun_transmittance(shade_fog_medium(), vec3(0.0, u_eye_above_ground + p_rel_eye.y, 0.0),
                                            u_fog_sun_dir)
                    : 1.0;
  float visibility = cos_sun <= 0.0 || sun_transmittance == 0.0
                         ? 0.0
                         : sun_visibility(u_eye_rel_light + p_rel_eye, n_geometric, shadow_offset_m);
  return surface_radiance(albedo, n, l, view, specular, u_sky, u_sun_radiance * sun_transmittance, cos_sun,
                          visibility);
#else
  float visibility =
      cos_sun <= 0.0 ? 0.0 : sun_visibility(u_eye_rel_light + p_rel_eye, n_geometric, shadow_offset_m);
  return surface_radiance(albedo, n, l, view, specular, u_sky, u_sun_radiance, cos_sun, visibility);
#endif
#else
  return sky_ambient(albedo, n, u_sky);
#endif
}

void main() {
  ivec2 texel = ivec2(gl_FragCoord.xy);
  vec2 pixel = vec2(gl_FragCoord.x - 0.5 + u_jitter.x, u_image_size.y - gl_FragCoord.y - 0.5 + u_jitter.y);
  vec3 dir = camera_ray_direction(pixel);
  vec3 view = -normalize(dir);
  vec4 normal_distance = texelFetch(g_normal_distance, texel, 0);
  bool plant_hit = normal_distance.w >= 0.0;
  float plant_t = plant_hit ? normal_distance.w / length(dir) : kInfinity;
  float ground_t = ground_distance(u_eye_above_ground, dir.y);
#ifdef FOG
  // T(0, t_end) along the unit direction, t_end in metres (+inf for the sky).
  float fog_t_end = min(plant_t, ground_t) * length(dir);
  float transmittance = fog_transmittance(shade_fog_medium(), vec3(0.0, u_eye_above_ground, 0.0), -view, 0.0, fog_t_end);
  if (!plant_hit && !(ground_t < kInfinity)) {
    colour = vec4(transmittance * sky_radiance(u_sky), 1.0);
    return;
  }
#else
  if (!plant_hit && !(ground_t < kInfinity)) {
    colour = vec4(sky_radiance(u_sky), 1.0);
    return;
  }
#endif
  // What is seen, then one call of lit(): a SIMD rasteriser (llvmpipe) runs both sides of
  // a branch, so the shadow lookup is written once.
  vec3 albedo, n, n_geometric;
  float t;
  float specular;
  float shadow_offset_m = 0.0;
  if (ground_t < plant_t) {
    albedo = u_ground_albedo;
    n = n_geometric = kGroundNormal;
    t = ground_t;
    specular = 0.0;
  } else {
    vec4 geometric_u = texelFetch(g_geometric_u, texel, 0);
    uvec4 ids = texelFetch(g_ids, texel, 0);
    uint plant = ids.x & PLANT_INDEX_MASK;
    uint material = ids.x >> PLANT_INDEX_BITS;
    bool wood = material == 0u && ids.y != LEAF_CHAIN;  // a leaf is never bark (materials.md)
    vec4 decided = texelFetch(g_albedo, texel, 0);
    bool in_table = material < uint(u_material_count);
    int slot = in_table ? int(material) : 0;
    albedo = decided.a > 0.0                     ? decided.rgb
             : wood && plant_bark[plant].w > 0.0 ? plant_bark[plant].rgb
             : in_table                          ? u_material_albedo[slot]
                                                 : u_material_albedo_beyond;
    n = normal_distance.xyz;
    n_geometric = geometric_u.xyz;
    t = plant_t;
    specular = in_table ? u_material_specular[slot] : 1.0;
#ifdef SUN
    if (wood && plant_maps[plant].relief_depth_m > 0.0) shadow_offset_m = t * u_pixel_step_rad;
#endif
  }
#ifdef FOG
  colour = vec4(transmittance * lit(albedo, n, n_geometric, t * dir, view, specular, shadow_offset_m), 1.0);
#else
  colour = vec4(lit(albedo, n, n_geometric, t * dir, view, specular, shadow_offset_m), 1.0);
#endif
}
