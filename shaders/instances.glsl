// instances.glsl — the per-plant transforms of the instanced draws (INSTANCED), shared by
// the frusta (frusta.vert.glsl, frusta.frag.glsl) and the leaves and polygon baseline
// (mesh.vert.glsl): one draw per shared skeleton, instance u_instance_base + gl_InstanceID.

#ifdef INSTANCED
// Plants that share a skeleton (docs/scatter.md "Instancing"): the skeleton's records once,
// in its own frame, drawn once per plant through the plant's place_plant transform
// p_world = position + R_y·(scale·p) (core/scene/instances.h), position as hi + lo floats. own = 1:
// the identity standing for the plants skinned in the world, whose records keep their
// frames and plants (drawn exactly as without INSTANCED). core/gl/gl_instances.h mirrors it.
struct GpuInstance {
  vec3 position_hi;
  float scale;
  vec3 position_lo;
  float cos_y;
  float sin_y;
  uint plant;
  uint own;
  uint pad;
};
layout(std430, binding = INSTANCES_BINDING) readonly buffer Instances { GpuInstance instances[]; };
uniform uint u_instance_base;  // the draw's first instance (one draw per shared skeleton)

// R_y·v and R_yᵀ·v, as PlantTransform::rotate / unrotate.
vec3 instance_rotate(GpuInstance g, vec3 v) { return vec3(g.cos_y * v.x + g.sin_y * v.z, v.y, -g.sin_y * v.x + g.cos_y * v.z); }
vec3 instance_unrotate(GpuInstance g, vec3 v) { return vec3(g.cos_y * v.x - g.sin_y * v.z, v.y, g.sin_y * v.x + g.cos_y * v.z); }
#endif
