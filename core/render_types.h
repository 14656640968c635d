// render_types.h — what every renderer takes and gives (the CPU reference, core/cpu/
// render_cpu.h, and the GL backend, core/gl/render_gl.h): the options of a render, its
// images and the passes it ran. No renderer's code is needed to read or write them.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/relief.h"
#include "core/skin.h"

namespace sylva {

// Which AOVs to compute (bit flags).
enum AovFlags : uint32_t {
  kAovDepth = 1u << 0,   // channel Z
  kAovNormal = 1u << 1,  // N.X N.Y N.Z
  kAovUv = 1u << 2,      // U V
  kAovId = 1u << 3,      // id.plant id.chain id.segment
};

// Which geometry stands for the plants (issue 3: the analytic frusta are the reference,
// the tessellated meshes the polygon baseline).
enum class GeometryKind : uint8_t {
  frusta,  // analytic conical frusta (frustum_tracer.h), relief-mapped where asked
  mesh,    // the frusta tessellated at GS level mesh_level (tessellate.h), in Embree
};

struct GeometryOptions {
  GeometryKind kind = GeometryKind::frusta;
  int mesh_level = 2;   // m: 16·4^m triangles per segment
  bool cull = true;     // leave out plants that can affect no pixel (outside the view
                        // frustum and casting no shadow into it; culling.h)
  bool displace = true; // mesh: displace each plant's mesh by its height map where it has
                        // one (the paper's GS+R; tessellate.h displace)
  bool relief = true;   // frusta: relief-map every plant whose bark has a height map and a
                        // relief_depth > 0 (relief.h, paper sec. 3); no height map, no marching
  ReliefOptions relief_options;  // how the relief marcher samples
};

struct RenderOptions {
  uint32_t spp = 1;                             // samples per pixel, >= 1
  uint32_t aovs = 0;                            // AovFlags
  unsigned threads = 0;                         // 0: every core
  const std::atomic<bool>* cancel = nullptr;    // set (e.g. by SIGINT) to stop early
  bool progress = false;                        // progress bar on stderr after 1 s
  SkinOptions skin;                             // how plants are skinned
  GeometryOptions geometry;                     // what stands for the plants
};

// Float images, row-major from the top-left pixel, channels interleaved.
struct RenderImage {
  uint32_t width = 0, height = 0;
  std::vector<float> beauty;  // RGBA, linear
  std::vector<float> depth;   // Z; empty unless kAovDepth
  std::vector<float> normal;  // N.X N.Y N.Z; empty unless kAovNormal
  std::vector<float> uv;      // U V; empty unless kAovUv
  std::vector<float> id;      // id.plant id.chain id.segment; empty unless kAovId
};

// One pass of the render and what it cost.
struct RenderPass {
  std::string name;    // "skin", "bvh build", "trace", "shade", ...
  double seconds = 0;  // wall time; for per-thread passes, summed thread time
  std::string detail;  // counts: "412 frusta", "786432 rays"
};

struct RenderResult {
  RenderImage image;
  std::vector<RenderPass> passes;
  bool cancelled = false;     // stopped by options.cancel: the image is incomplete
  uint64_t frusta = 0;
  uint64_t geometry_bytes = 0;  // what the traced geometry holds (SceneTracer::memory_bytes)
  uint64_t primary_rays = 0;
  uint64_t shadow_rays = 0;
};

}  // namespace sylva
