// gl_fog.h — the fog's buffers on the GPU (render_gl.cpp; docs/gl-fog.md): for the cone modes
// the shadow cones, uploaded once per (plants, sun) as apex-free conical frusta
// (shaders/shadow_cones.glsl), and the per-pixel lists of their intervals along the camera
// rays that the cone pass appends to (shaders/fog_lists.glsl) and the fog resolve reads; for
// mode map the sun-space depth maps (core/light/sun_map.h), uploaded once per (plants, sun)
// as the CPU built them (shaders/fog_map.glsl walks them).
// Preconditions: as gl_objects.h. Failures throw GlError.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>

#include "core/gl/bindings.h"
#include "core/gl/gl_objects.h"
#include "core/light/shadow_cones.h"
#include "core/light/sun_map.h"

namespace sylva {

// A cone set on the GPU: one GpuShadowConeRecord per cone (shadow_cones.h cone_geometry),
// positions relative to `origin` (the bases' mean, in double) so that float keeps them.
struct GlFogCones {
  GlBuffer records;
  uint32_t count = 0;
  glm::dvec3 origin{0};
  uint64_t bytes = 0;
};
GlFogCones upload_fog_cones(const ConeSet& set);

// Sun maps on the GPU: a GpuSunMapRecord per map, positions relative to `origin` (the first
// map's centre, in double); every map's tile slots (made global: the map's first slot
// added), every slot's height range and texels, each in one buffer (bindings.h).
struct GlFogMaps {
  GlBuffer records, slots, ranges, texels;
  uint32_t count = 0;
  glm::dvec3 origin{0};
  uint64_t bytes = 0;
  void bind() const;  // at bindings.h's kFogMapsBinding .. kFogMapTexelsBinding
};
// Throws GlError for more than kFogMaxMaps maps or none.
GlFogMaps upload_fog_maps(std::span<const SunDepthMap> maps);

// The per-pixel interval lists: linked lists in shader storage, a node per cone fragment
// taken with an atomic counter. A fragment that finds the node buffer full marks its pixel
// incomplete; the resolve marches that pixel whole (brute: unbiased, slower) and counts it.
struct GlFogLists {
  uint32_t pixels = 0;    // heads and overflow flags
  uint32_t capacity = 0;  // nodes
  GlBuffer nodes, heads, overflow, counters;

  // Buffers for `pixels` pixels and `capacity` nodes; reallocated only when one grows.
  // Returns the buffers (re)allocated.
  uint32_t reserve(uint32_t pixels, uint32_t capacity);
  void bind() const;            // at bindings.h's kFogNodesBinding .. kFogCountersBinding
  void clear_frame() const;     // counters and overflow flags to 0
  void clear_pass() const;      // heads to kFogListEnd, next_node to 0 (before a cone pass)
  gl::GlFogCounters read_counters() const;  // waits for the GPU
  uint64_t bytes() const {
    return uint64_t{capacity} * sizeof(gl::FogNodeRecord) + uint64_t{pixels} * 8 + sizeof(gl::GlFogCounters);
  }
};

}  // namespace sylva
