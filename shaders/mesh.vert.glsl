// mesh.vert.glsl — the polygon baseline (Bhagvat et al. 2009 sec. 4, GS and GS+R): one vertex of a
// tessellated mesh (tessellate.h) as core/gl_mesh.cpp uploads it, projected as
// frusta.vert.glsl projects a bounding pyramid's corner (views.glsl), so both fill one
// G-buffer alike.
//
// Frames: a position is stored relative to its plant's origin_hi (a float-exact point near
// the plant); the eye (or the shadow map's centre) comes as hi + lo floats, so
// eye − origin_hi = (eye_hi − origin_hi) + eye_lo keeps float precision at 10^6 m, as in
// frusta_common.glsl. Every vertex of a plant shares one origin, so the vertices that
// tessellate copies across a joint stay bit-identical here: the mesh stays watertight.
// INSTANCED: a shared skeleton's triangles, stored once in its frame, drawn once per plant
// (instances.glsl, docs/scatter.md "Instancing").

layout(location = 0) in vec3 a_position;  // metres, relative to the plant's origin_hi
layout(location = 1) in vec3 a_normal;    // unit shading normal (tessellate.h, or displace's)
layout(location = 2) in vec2 a_uv;        // u turns, v_m metres
layout(location = 3) in uint a_frustum;   // index into mesh_frusta

// Per frustum (gl_mesh.cpp's MeshFrustumRecord): its plant's origin_hi (xyz), and
// plant | material << 24, chain, segment (knuckle: joint) index, 0.
struct MeshFrustum {
  vec4 origin_hi;
  uvec4 ids;
};
layout(std430, binding = MESH_FRUSTA_BINDING) readonly buffer MeshFrusta { MeshFrustum mesh_frusta[]; };

#if defined(SHADOW_PASS) && defined(LEAF_IMAGES)
out vec3 v_normal;          // the leaf's Newell normal (one-sided leaves: which side this is)
out vec2 v_uv;              // the leaf's uv (cut-outs)
flat out uvec4 v_ids;
#endif
#ifdef GBUFFER_PASS
out vec3 v_rel_eye;         // position − eye: the distance, and the ray it lies on
out vec3 v_local;           // position − origin_hi: the triangle's plane (geometric normal)
out vec3 v_normal;
out vec2 v_uv;
flat out uvec4 v_ids;       // plant | material << 24, chain, segment, a leaf's back material + 1 (0: none)
#endif

void main() {
  MeshFrustum f = mesh_frusta[a_frustum];
  // views.glsl's projections, as frusta.vert.glsl's: a triangle's depth is that of the
  // ray-cast frusta for the same point, in the G-buffer and in the shadow map.
#ifdef SHADOW_PASS
  vec3 view_hi = u_light_hi, view_lo = u_light_lo;  // the shadow map's centre
#else
  vec3 view_hi = u_eye_hi, view_lo = u_eye_lo;
#endif
  vec3 rel = a_position - ((view_hi - f.origin_hi.xyz) + view_lo);  // relative to the view
  vec3 local = a_position;  // in the plant's frame, at the plant's scale
  vec3 normal = a_normal;
  vec2 uv = a_uv;
  uvec4 ids = f.ids;
#ifdef INSTANCED
  // A plant drawn through its transform (instances.glsl; own: one skinned in the world, as
  // without INSTANCED): the vertex taken to the world relative to the view as
  // frusta.vert.glsl takes a pyramid's corner, the normal turned, v_m in world metres (a
  // leaf's v is its own, leaf_mesh.h leaf_uvs), the ids the instance's plant.
  GpuInstance inst = instances[u_instance_base + uint(gl_InstanceID)];
  if (inst.own == 0u) {
    vec3 view_rel = (view_hi - inst.position_hi) + (view_lo - inst.position_lo);
    rel = inst.scale * instance_rotate(inst, a_position + f.origin_hi.xyz) - view_rel;
    local = inst.scale * instance_rotate(inst, a_position);
    normal = instance_rotate(inst, a_normal);
    if (ids.y != LEAF_CHAIN) uv.y *= inst.scale;
    ids.x = (ids.x & ~PLANT_INDEX_MASK) | inst.plant;
  }
#endif
#ifdef SHADOW_PASS
  gl_Position = light_clip_position(rel);
#ifdef LEAF_IMAGES
  v_normal = normal;
  v_uv = uv;
  v_ids = ids;
#endif
#else
  gl_Position = camera_clip_position(rel);
  v_rel_eye = rel;
  v_local = local;
  v_normal = normal;
  v_uv = uv;
  v_ids = ids;
#endif
}
