// bark.glsl — a plant's bark maps on the GPU, the GLSL side of core/texture.h: per-plant
// texture parameters, the height fields the relief marcher reads (relief.glsl), and the
// albedo lookup over a ray-differential footprint, sRGB decoded after filtering.
//
// Texture coordinates as texture.h: s = u·u_repeat (u in turns), t = v_m·v_per_metre (v_m
// in metres), both periodic; texel row 0 is t = 0. The renderer (core/render_gl.cpp)
// uploads each distinct image once:
//   - as a texture with its full MIP chain (GL_REPEAT, trilinear), bound at texture unit
//     i for u_bark_textures[i]: albedo as GL_RGBA8 holding the file's sRGB-encoded values
//     (not an sRGB format: the filter averages encoded values and segment_albedo decodes the
//     result, as the CPU's TextureSystem lookup does); a height map as GL_R32F;
//   - a height map's finest level also as floats in height_texels, sampled bilinearly in
//     float exactly as texture.cpp's HeightTexture::height (the relief's geometry is that
//     one surface for every ray, primary and shadow alike).
// A program that samples (BARK_TEXTURE_UNITS defined: the number of distinct images of the
// scene) selects the texture by a loop over constant indices: an array of samplers may
// only be indexed by a dynamically uniform expression, and the plant varies per fragment.
// Mesh shaders include this file for the same lookups (segment_albedo).

#ifndef kInfinity  // ray_frustum.glsl's, where it comes first
#define kInfinity uintBitsToFloat(0x7F800000u)
#endif

// Per plant, indexed by the plant index of segment_ids / the G-buffer.
struct PlantMaps {
  float u_repeat;        // s = u·u_repeat
  float v_per_metre;     // t = v_m·v_per_metre
  float relief_depth_m;  // > 0: relief-mapped (a height map, GeometryOptions::relief, depth > 0)
  int albedo_unit;       // u_bark_textures index of material 0's albedo map; −1: material_maps[0]
                         // decides; −2: none (the bark's colour)
  int height_unit;       // u_bark_textures index of the height map (MIP-mapped); −1: none
  uint height_first;     // the height map's first texel in height_texels
  int height_width;      // its finest level's size in texels
  int height_height;
};
layout(std430, binding = PLANT_MAPS_BINDING) readonly buffer PlantMapsBuffer { PlantMaps plant_maps[]; };
layout(std430, binding = HEIGHT_TEXELS_BINDING) readonly buffer HeightTexels { float height_texels[]; };

// HeightTexture::height of texture.cpp: bilinear, periodic, texel i's centre at
// s = (i + 0.5)/width.
float height_field(PlantMaps maps, float s, float t) {
  int width = maps.height_width, height = maps.height_height;
  float x = (s - floor(s)) * float(width) - 0.5, y = (t - floor(t)) * float(height) - 0.5;
  float x0 = floor(x), y0 = floor(y);
  float fx = x - x0, fy = y - y0;
  int i0 = int(x0), j0 = int(y0);
  i0 = i0 < 0 ? i0 + width : (i0 >= width ? i0 - width : i0);
  j0 = j0 < 0 ? j0 + height : (j0 >= height ? j0 - height : j0);
  int i1 = i0 + 1 >= width ? 0 : i0 + 1, j1 = j0 + 1 >= height ? 0 : j0 + 1;
  uint row0 = maps.height_first + uint(j0 * width), row1 = maps.height_first + uint(j1 * width);
  float top = height_texels[row0 + uint(i0)] + fx * (height_texels[row0 + uint(i1)] - height_texels[row0 + uint(i0)]);
  float bottom = height_texels[row1 + uint(i0)] + fx * (height_texels[row1 + uint(i1)] - height_texels[row1 + uint(i0)]);
  return top + fy * (bottom - top);
}

// How u and v_m change from a pixel to the next (texture.h's UvFootprint): x to the
// right, y downward, turns and metres per pixel step. Zero: the finest MIP level.
struct UvFootprint {
  float du_dx;
  float dv_dx;
  float du_dy;
  float dv_dy;
};

// uv_footprint of texture.cpp (PBRT's ray differentials): the rays from `origin` along
// dir_dx and dir_dy (the neighbouring samples' directions) meet the tangent plane of the
// hit (position, geometric normal) at p_x, p_y; Δp ≈ dp_du·Δu + dp_dv·Δv_m solved by least
// squares. Degenerate cases give the zero footprint, never NaN. Positions in any frame
// shared by `position` and `origin` (the renderer's: relative to the eye).
UvFootprint uv_footprint(vec3 position, vec3 geometric_normal, vec3 dp_du, vec3 dp_dv, vec3 origin, vec3 dir_dx,
                         vec3 dir_dy) {
  UvFootprint none = UvFootprint(0.0, 0.0, 0.0, 0.0);
  vec3 n = geometric_normal;
  float a = dot(dp_du, dp_du), b = dot(dp_du, dp_dv), c = dot(dp_dv, dp_dv);
  float det = a * c - b * b;
  if (!(det > 1e-12 * a * c) || !(det < kInfinity)) return none;
  float du[2], dv[2];
  for (int i = 0; i < 2; ++i) {
    vec3 direction = i == 0 ? dir_dx : dir_dy;
    float denominator = dot(n, direction);
    float numerator = dot(n, position - origin);
    if (!(abs(denominator) > 1e-12 * length(direction))) return none;
    vec3 p = origin + (numerator / denominator) * direction;
    vec3 delta = p - position;
    float pu = dot(dp_du, delta), pv = dot(dp_dv, delta);
    du[i] = (c * pu - b * pv) / det;
    dv[i] = (a * pv - b * pu) / det;
    if (!(abs(du[i]) < kInfinity) || !(abs(dv[i]) < kInfinity)) return none;
  }
  return UvFootprint(du[0], dv[0], du[1], dv[1]);
}

#ifdef BARK_TEXTURE_UNITS
#if BARK_TEXTURE_UNITS > MAX_BARK_IMAGES
#error "more bark images than bindings.glsl gives units"
#endif
layout(binding = BARK_TEXTURES_UNIT) uniform sampler2D u_bark_textures[BARK_TEXTURE_UNITS];

// textureGrad on u_bark_textures[unit] (unit in [0, BARK_TEXTURE_UNITS)).
vec4 bark_texture_grad(int unit, vec2 st, vec2 d_dx, vec2 d_dy) {
  vec4 value = vec4(0.0);
  for (int i = 0; i < BARK_TEXTURE_UNITS; ++i)
    if (i == unit) value = textureGrad(u_bark_textures[i], st, d_dx, d_dy);
  return value;
}

// HeightTexture::filtered_height of texture.cpp: H MIP-filtered over about
// width_s × width_t texture units around (s, t) (the relief normal's footprint).
float height_field_filtered(PlantMaps maps, float s, float t, float width_s, float width_t) {
  return bark_texture_grad(maps.height_unit, vec2(s - floor(s), t - floor(t)), vec2(width_s, 0.0),
                           vec2(0.0, width_t)).r;
}

// Per material slot: the albedo image the scene's table lays on its segments (scene.h
// segment_texture), bindings.h's MaterialMapsRecord.
struct MaterialMaps {
  float u_repeat;
  float v_per_metre;
  int albedo_unit;  // u_bark_textures index; −1: none
  int unused;
};
layout(std430, binding = MATERIAL_MAPS_BINDING) readonly buffer MaterialMapsBuffer {
  MaterialMaps material_maps[];  // MAX_MATERIALS of them
};

// SceneTextures::albedo of texture.cpp: the linear albedo of the segments of `material` on
// plant `plant` at (u, v_m), filtered over `footprint`, with a = 1 — material 0's bark
// texture, else the table's image (segment_texture); vec4(0) where they have no albedo
// texture (then the material table or the bark colour applies: shade.frag.glsl).
vec4 segment_albedo(uint plant, uint material, float u, float v_m, UvFootprint footprint) {
  PlantMaps maps = plant_maps[plant];
  int unit = -1;
  float u_repeat = 1.0, v_per_metre = 1.0;
  if (material == 0u && maps.albedo_unit != -1) {
    unit = maps.albedo_unit;  // the bark's, or −2: its colour
    u_repeat = maps.u_repeat;
    v_per_metre = maps.v_per_metre;
  } else if (material < uint(MAX_MATERIALS)) {
    MaterialMaps entry = material_maps[material];
    unit = entry.albedo_unit;
    u_repeat = entry.u_repeat;
    v_per_metre = entry.v_per_metre;
  }
  if (unit < 0) return vec4(0.0);
  float s = u * u_repeat, t = v_m * v_per_metre;
  vec4 encoded = bark_texture_grad(unit, vec2(s - floor(s), t - floor(t)),
                                   vec2(footprint.du_dx * u_repeat, footprint.dv_dx * v_per_metre),
                                   vec2(footprint.du_dy * u_repeat, footprint.dv_dy * v_per_metre));
  return vec4(srgb_to_linear(encoded.rgb), 1.0);
}
#endif
