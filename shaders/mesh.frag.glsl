// mesh.frag.glsl — the polygon baseline's fragment (Bhagvat et al. 2009 sec. 4, GS and GS+R): what
// mesh_accel.cpp's MeshTracer::nearest reports for the ray through this fragment, written
// into the G-buffer exactly as frusta.frag.glsl writes a ray-cast hit (shade.frag.glsl
// reads both alike). No discard, no gl_FragDepth: the rasterised depth is the hit's.
//
// GBUFFER_PASS: the barycentric interpolation of the vertex normals, renormalised (the
// shading normal), the triangle's plane normal (geometric), both turned toward the eye as
// render_cpu.cpp's shade() does; the Euclidean distance; ids; u in [0, 1), v_m.
// SHADOW_PASS: depth only.
//
// BARK_TEXTURE_UNITS (bark.glsl comes first): the segment albedo of bark.glsl's segment_albedo
// over the footprint of texture.h's ray differentials. On a triangle (a plane with affine
// u, v_m) the neighbouring sample's ray meets the plane where u, v_m have moved by their
// screen derivatives, so the footprint is dFdx/dFdy of (u, v_m), one pixel / sqrt(spp)
// (u_footprint_scale). A cap fan, whose vertices share one v_m, has no uv parametrisation:
// the zero footprint there, as MeshTracer's zero dp_du, dp_dv give on the CPU.

#ifdef GBUFFER_PASS
in vec3 v_rel_eye;
in vec3 v_local;
in vec3 v_normal;
in vec2 v_uv;
flat in uvec4 v_ids;
#elif defined(LEAF_IMAGES)
in vec3 v_normal;
in vec2 v_uv;
flat in uvec4 v_ids;
#endif

#if defined(GBUFFER_PASS) || defined(LEAF_IMAGES)
// The material a ray along `ray_direction` sees here: a double-sided leaf's back material
// (ids.w − 1, gl_mesh.cpp; 0 none) where the ray runs along its normal, as LeafRef::
// material_seen_along; otherwise the ids' own.
uint side_material(vec3 ray_direction) {
  bool back = v_ids.y == LEAF_CHAIN && v_ids.w != 0u && dot(ray_direction, v_normal) > 0.0;
  return back ? v_ids.w - 1u : v_ids.x >> PLANT_INDEX_BITS;
}
#endif

// LEAF_IMAGES (the leaves, both passes; leaf_images.h): material m's layer u_leaf_layer[m]
// of the 2D array (RGB sRGB-encoded albedo, A the cut-out; GL_LINEAR, clamped, no MIP
// levels: LeafImages::sample's filter), its flags u_leaf_flags[m]: 1 albedo image, 2
// cut-out, 4 one-sided. A fragment is discarded where the leaf is not: alpha below
// LEAF_ALPHA_CUTOFF, or the back of a one-sided leaf — the side the ray arrives from
// (the eye's in the G-buffer pass, the sun's in the shadow pass, whose rays run along
// −u_light_dir) — as LeafTracer's filter lets those rays through.
#ifdef LEAF_IMAGES
layout(binding = LEAF_IMAGES_UNIT) uniform sampler2DArray u_leaf_images;
uniform int u_leaf_layer[MAX_MATERIALS];
uniform uint u_leaf_flags[MAX_MATERIALS];
const float LEAF_ALPHA_CUTOFF = 0.5;

// Material `material`'s layer and flags; a material past the table has neither (the
// table's indices stop at MAX_MATERIALS − 1: LeafImages::layer_of).
int leaf_layer(uint material) { return material < uint(MAX_MATERIALS) ? u_leaf_layer[material] : -1; }
uint leaf_flags(uint material) { return material < uint(MAX_MATERIALS) ? u_leaf_flags[material] : 0u; }

// The leaf image's texel at the leaf's (u, v): v = 0 the image's bottom row.
vec4 leaf_texel(uint material) {
  int layer = leaf_layer(material);
  return layer < 0 ? vec4(1.0) : texture(u_leaf_images, vec3(v_uv.x, 1.0 - v_uv.y, float(layer)));
}

// Whether the leaf is missing at this fragment for a ray along `ray_direction`.
bool leaf_missing(uint material, vec4 texel, vec3 ray_direction) {
  uint flags = leaf_flags(material);
  if ((flags & 4u) != 0u && dot(ray_direction, v_normal) > 0.0) return true;
  return (flags & 2u) != 0u && texel.a < LEAF_ALPHA_CUTOFF;
}
#endif

#ifdef GBUFFER_PASS

layout(location = 0) out vec4 g_normal_distance;  // shading normal (toward the eye), distance
layout(location = 1) out vec4 g_geometric_u;      // geometric normal (toward the eye), u
layout(location = 2) out uvec4 g_ids;             // plant | material << 24, chain, segment, v_m bits
layout(location = 3) out vec4 g_albedo;           // a = 1: bark texture albedo; a = 0: the material table
#ifdef BARK_TEXTURE_UNITS
uniform float u_footprint_scale;  // 1 / sqrt(spp): the ray differentials' step
#endif
#endif

void main() {
#if defined(SHADOW_PASS) && defined(LEAF_IMAGES)
  // The light meets the side its rays (along −u_light_dir) arrive at.
  uint shadow_material = side_material(-u_light_dir);
  if (leaf_missing(shadow_material, leaf_texel(shadow_material), -u_light_dir)) discard;
#endif
#ifdef GBUFFER_PASS
  uint material = side_material(v_rel_eye);
#ifdef LEAF_IMAGES
  // Sampled in uniform control flow (before any discard), so the helper pixels agree.
  uint leaf_material = material;
  vec4 leaf = leaf_texel(leaf_material);
  if (leaf_missing(leaf_material, leaf, v_rel_eye)) discard;
#endif
  // The triangle's plane: any two differences of interpolated points of it lie in it
  // (perspective-correct interpolation keeps them on the plane, helper pixels extrapolate
  // it). Taken in the plant's frame, whose coordinates are a plant's size, not the eye's
  // distance: the tangents keep float precision. The sign does not matter (turned below).
  vec3 n_geometric = cross(dFdx(v_local), dFdy(v_local));
  float n_geometric_length = length(n_geometric);
  float n_shading_length = length(v_normal);
  vec3 n_shading = n_shading_length > 0.0 ? v_normal / n_shading_length : vec3(0.0);
  if (n_geometric_length > 0.0) n_geometric /= n_geometric_length;
  else n_geometric = n_shading;  // a triangle seen exactly edge-on: no plane to measure
  if (!(n_shading_length > 0.0)) n_shading = n_geometric;
  vec3 view = -v_rel_eye;
  if (dot(n_geometric, view) < 0.0) n_geometric = -n_geometric;  // seen from inside
  if (dot(n_shading, view) < 0.0) n_shading = -n_shading;
  // tessellate.h gives the seam column u = 1 on the triangles before it: [0, 1) as skin.h.
  // A leaf's u is its own, in [0, 1] (leaf_mesh.h leaf_uvs), as LeafTracer reports it.
  float u = v_ids.y == LEAF_CHAIN ? clamp(v_uv.x, 0.0, 1.0) : v_uv.x - floor(v_uv.x);
  g_normal_distance = vec4(n_shading, length(v_rel_eye));
  g_geometric_u = vec4(n_geometric, u);
  g_ids = uvec4((v_ids.x & PLANT_INDEX_MASK) | (material << PLANT_INDEX_BITS), v_ids.yz,
                floatBitsToUint(v_ids.y == LEAF_CHAIN ? clamp(v_uv.y, 0.0, 1.0) : v_uv.y));
#ifdef BARK_TEXTURE_UNITS
  // Derivatives first, in uniform control flow; the image rows run downward (texture.h's y).
  vec2 duv_dx = dFdx(v_uv) * u_footprint_scale, duv_dy = -dFdy(v_uv) * u_footprint_scale;
  bool cap = abs(duv_dx.y) + abs(duv_dy.y) <= 1e-5 * abs(v_uv.y);  // one v_m: rounding only
  UvFootprint footprint = cap ? UvFootprint(0.0, 0.0, 0.0, 0.0)
                              : UvFootprint(duv_dx.x, duv_dx.y, duv_dy.x, duv_dy.y);
  // The bark covers the wood only (material 0), the table's images their materials.
  g_albedo = segment_albedo(v_ids.x & PLANT_INDEX_MASK, material, u, v_uv.y, footprint);
#elif defined(LEAF_IMAGES)
  // A leaf image's albedo, decoded after filtering as LeafImages::albedo (and bark.glsl).
  bool image = (leaf_flags(leaf_material) & 1u) != 0u;
  g_albedo = image ? vec4(srgb_to_linear(leaf.rgb), 1.0) : vec4(0.0);
#else
  g_albedo = vec4(0.0);
#endif
#endif
}
