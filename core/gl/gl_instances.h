// gl_instances.h — what the GL backend's instanced draws share (docs/scatter.md,
// "Instancing"): the per-plant transform record the shaders read (shaders/instances.glsl's
// GpuInstance at INSTANCES_BINDING) and the split of a scene's plants into those skinned in
// the world and the groups drawn through their transforms. The frusta (render_gl.cpp), the
// leaves and the polygon baseline (gl_mesh.h) each make their own split with this one rule.
//
// A group is the plants of one distinct skeleton (instances.h plant_instances) that may be
// drawn through a transform (the caller's `instanceable`: the geometry is the same in the
// skeleton's frame wherever the plant stands); a group of one plant is skinned in the world
// instead (a transform would save nothing). With instancing off, every plant is in the world.
//
// Frames: a GpuInstance takes a point p of its skeleton's frame to the world as
// position + R_y·(scale·p) (PlantTransform), position as hi + lo floats so that the
// shaders' (eye_hi − position_hi) + (eye_lo − position_lo) keeps float precision at 10^6 m.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/scene/instances.h"
#include "core/scene/scene.h"

namespace sylva {

// instances.glsl's GpuInstance (std430: vec3 + float packs into 16 bytes).
struct GpuInstance {
  float position_hi[3];
  float scale;
  float position_lo[3];
  float cos_y;
  float sin_y;
  uint32_t plant;
  uint32_t own;  // 1: the identity of the plants skinned in the world
  uint32_t pad;
};
static_assert(sizeof(GpuInstance) == 48);

// `t` for plant `plant`; own: the identity standing for the plants skinned in the world.
GpuInstance gpu_instance(const PlantTransform& t, uint32_t plant, bool own);

struct GlInstanceGroups {
  std::vector<uint32_t> world;                // plants skinned in the world, ascending
  std::vector<std::vector<uint32_t>> groups;  // per shared skeleton its plants (≥ 2, ascending);
                                              // the first stands for the skeleton
  bool instanced() const { return !groups.empty(); }
};

// Splits `scene`'s plants (every skeleton set). `instance`: RenderOptions::geometry.instance;
// false puts every plant in the world. `instanceable(p)`: whether plant p may be drawn
// through its transform.
GlInstanceGroups gl_instance_groups(const Scene& scene, bool instance,
                                    const std::function<bool(uint32_t)>& instanceable);

}  // namespace sylva
