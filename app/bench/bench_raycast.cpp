// bench_raycast.cpp — `sylva bench raycast`: primary rays per second on a preset, sylva's
// own BVH + analytic frusta against Embree 3 in the same run.
//
// Methods (docs/benchmarks.md, "Primary rays"), all tracing the same camera rays of the preset's default
// scene, nearest hit only:
//   sylva-bvh        sylva's SAH BVH (core/bvh.h) calling intersect_frustum (double)
//   embree-user      Embree user geometry through FrustumAccel, as the CPU renderer traces:
//                    Embree's BVH calling the same intersect_frustum with the double ray
//   embree-curves    Embree's native round linear curves on the same skeleton (cones with
//                    spheres at the joints: a different surface at the joints)
//   embree-mesh-mN   Embree triangles: the frusta tessellated at GS level N (tessellate.h),
//                    traced as the renderer traces them (MeshTracer, mesh_accel.h: the hit
//                    recomputed and described in double); bytes: the mesh's arrays plus
//                    Embree's structure
// For each: rays per second on 1 thread and on all threads, the depth error against the
// analytic reference (sylva-bvh: hit/miss disagreement and RMS distance error over pixels
// both hit, relative to the scene's size), and bytes per segment of the structure.
#include <embree3/rtcore.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "app/bench/bench_metrics.h"
#include "app/bench/bench.h"
#include "core/cpu/bvh.h"
#include "core/cpu/frustum_accel.h"
#include "core/cpu/mesh_accel.h"
#include "core/cpu/render_cpu.h"
#include "core/scene/scene.h"
#include "core/geometry/crotch_mesh.h"
#include "core/geometry/tessellate.h"
#include "core/grow/turtle.h"
#include "core/grow/grow.h"
#include "core/util/clock.h"
#include "core/util/parallel.h"

namespace sylva::cli {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct MethodResult {
  std::string name;
  double rays_per_s_1 = 0;
  double rays_per_s_all = 0;
  double miss_disagreement = 0;  // fraction of pixels where hit/miss differs from the reference
  double depth_rms_rel = 0;      // RMS |t − t_ref|·|d| over pixels both hit, / scene diagonal
  double bytes_per_segment = 0;
};

// Runs `trace(first_ray, end_ray, depths)` over all rays on `threads` threads; returns the
// best wall time of `repeats` runs.
double time_trace(size_t rays, unsigned threads, int repeats,
                  const std::function<void(size_t, size_t)>& trace) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    constexpr size_t kChunk = 4096;  // rays per work item
    parallel_for((rays + kChunk - 1) / kChunk, threads, nullptr, [&](size_t chunk, unsigned) {
      trace(chunk * kChunk, std::min(rays, (chunk + 1) * kChunk));
    });
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// Bytes Embree allocates, counted by its memory monitor.
std::atomic<int64_t> g_embree_bytes{0};
bool embree_memory_monitor(void*, ssize_t bytes, bool) {
  g_embree_bytes += bytes;
  return true;
}

// Traces rays [b, e) through an Embree scene, storing distances (t·|d|) or +inf.
void trace_embree(RTCScene scene, const std::vector<Ray>& rays, size_t b, size_t e, std::vector<double>& depth) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  for (size_t i = b; i < e; ++i) {
    RTCRayHit rh{};
    rh.ray.org_x = static_cast<float>(rays[i].origin.x);
    rh.ray.org_y = static_cast<float>(rays[i].origin.y);
    rh.ray.org_z = static_cast<float>(rays[i].origin.z);
    rh.ray.dir_x = static_cast<float>(rays[i].direction.x);
    rh.ray.dir_y = static_cast<float>(rays[i].direction.y);
    rh.ray.dir_z = static_cast<float>(rays[i].direction.z);
    rh.ray.tnear = 0;
    rh.ray.tfar = kInf;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    depth[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? std::numeric_limits<double>::infinity()
                                                         : rh.ray.tfar * glm::length(rays[i].direction);
  }
}

void compare(const std::vector<double>& ref, const std::vector<double>& got, double scale, MethodResult& r) {
  size_t disagree = 0, both = 0, any = 0;
  double sum_sq = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    const bool a = std::isfinite(ref[i]), b = std::isfinite(got[i]);
    if (a || b) ++any;
    if (a != b) ++disagree;
    if (a && b) {
      ++both;
      sum_sq += (ref[i] - got[i]) * (ref[i] - got[i]);
    }
  }
  r.miss_disagreement = any ? static_cast<double>(disagree) / static_cast<double>(any) : 0;
  r.depth_rms_rel = both ? std::sqrt(sum_sq / static_cast<double>(both)) / scale : 0;
}

void print_raycast_help() {
  std::cout << "usage: sylva bench raycast [PRESET] [--width W --height H] [--csv FILE] [--quick]\n\n"
               "Primary rays per second on a preset (default pine, 1024x768): sylva's BVH and\n"
               "analytic frusta against Embree user geometry, round curves and tessellated\n"
               "meshes, on one thread and all threads, with depth error and bytes per segment.\n"
               "--csv FILE writes the rows; --quick uses 256x192 and one repeat (a smoke test,\n"
               "not a measurement).\n";
}

}  // namespace

int run_bench_raycast(const std::vector<std::string>& args) {
  std::string preset = "pine";
  uint32_t width = 1024, height = 768;
  int max_level = 3, repeats = 3;
  std::string csv;
  bool help = false;
  FlagTable flag_table;
  flag_table.flags = {
      help_at_once(help),
      switch_flag({"--quick"}, [&] { width = 256, height = 192, max_level = 1, repeats = 1; }),
      count_flag({"--width"}, width, 16384),
      count_flag({"--height"}, height, 16384),
      text_flag({"--csv"}, csv),
  };
  flag_table.positional = [&preset](const std::string& name) { preset = name; };
  parse_flags(std::span(args).subspan(1), flag_table);  // args[0] is "raycast"
  if (help) {
    print_raycast_help();
    return kOk;
  }
  const std::string path = std::string(SYLVA_PRESETS_DIR) + "/" + preset + ".lsys";
  auto g = lsys::load_grammar(path);
  if (!g) {
    std::cerr << g.error().format();
    return kInputError;
  }
  auto grown = grow(*g, {}, path, {});
  if (!grown) {
    std::cerr << grown.error().format();
    return kInputError;
  }
  Scene scene = default_scene_for(grown->skeleton, width, height);
  SkinOptions exact;  // the frusta alone (the smooth skin blends its crotches: rows crotch-blend below)
  exact.blend_crotches = false;
  SceneGeometry geometry = build_scene_geometry(scene, exact);
  const Bvh bvh = build_bvh(geometry.frusta);  // sylva's own BVH, the measured alternative
  const size_t segments = grown->skeleton.segment_count();
  std::vector<Ray> rays;
  rays.reserve(static_cast<size_t>(width) * height);
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) rays.push_back(camera_ray(scene, x + 0.5, y + 0.5));
  const unsigned all = worker_count(0);
  double scale = 0;
  {
    Aabb box{glm::dvec3(std::numeric_limits<double>::infinity()), glm::dvec3(-std::numeric_limits<double>::infinity())};
    for (const Frustum& f : geometry.frusta) {
      Aabb b = frustum_bounds(f.shape);
      box.lo = glm::min(box.lo, b.lo);
      box.hi = glm::max(box.hi, b.hi);
    }
    scale = glm::length(box.hi - box.lo);
  }
  std::printf("sylva bench raycast: %s, %zu segments, %zu frusta, %ux%u primary rays, %u threads max\n",
              preset.c_str(), segments, geometry.frusta.size(), width, height, all);

  std::vector<MethodResult> results;
  std::vector<double> reference(rays.size()), depth(rays.size());
  {
    MethodResult r{"sylva-bvh"};
    auto trace = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        BvhHit h = intersect_nearest(bvh, geometry.frusta, rays[i], 0, std::numeric_limits<double>::infinity());
        reference[i] = h.hit_any() ? h.hit.t * glm::length(rays[i].direction) : std::numeric_limits<double>::infinity();
      }
    };
    r.rays_per_s_1 = static_cast<double>(rays.size()) / time_trace(rays.size(), 1, repeats, trace);
    r.rays_per_s_all = static_cast<double>(rays.size()) / time_trace(rays.size(), all, repeats, trace);
    r.bytes_per_segment = static_cast<double>(geometry.frusta.size() * sizeof(Frustum) +
                                              bvh.nodes.size() * sizeof(BvhNode)) /
                          static_cast<double>(segments);
    results.push_back(r);
  }

  RTCDevice device = rtcNewDevice(nullptr);
  rtcSetDeviceMemoryMonitorFunction(device, embree_memory_monitor, nullptr);
  auto run_embree = [&](const std::string& name, const std::function<void(RTCScene)>& fill) {
    g_embree_bytes = 0;
    RTCScene scene_e = rtcNewScene(device);
    fill(scene_e);
    rtcCommitScene(scene_e);
    MethodResult r{name};
    auto trace = [&](size_t b, size_t e) { trace_embree(scene_e, rays, b, e, depth); };
    r.rays_per_s_1 = static_cast<double>(rays.size()) / time_trace(rays.size(), 1, repeats, trace);
    r.rays_per_s_all = static_cast<double>(rays.size()) / time_trace(rays.size(), all, repeats, trace);
    compare(reference, depth, scale, r);
    r.bytes_per_segment = static_cast<double>(g_embree_bytes.load()) / static_cast<double>(segments);
    rtcReleaseScene(scene_e);
    results.push_back(r);
  };

  {
    // Embree user geometry as the CPU renderer traces it (core/cpu/frustum_accel.h): the
    // exact double ray reaches intersect_frustum. (Building the Ray from Embree's float
    // ray instead flips grazing silhouette pixels: 0.004 % of the pine's, depth RMS 7e-4.)
    const FrustumAccel accel(geometry.frusta);
    MethodResult r{"embree-user"};
    auto trace = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const BvhHit h = accel.nearest(rays[i], 0, std::numeric_limits<double>::infinity());
        depth[i] = h.hit_any() ? h.hit.t * glm::length(rays[i].direction) : std::numeric_limits<double>::infinity();
      }
    };
    r.rays_per_s_1 = static_cast<double>(rays.size()) / time_trace(rays.size(), 1, repeats, trace);
    r.rays_per_s_all = static_cast<double>(rays.size()) / time_trace(rays.size(), all, repeats, trace);
    compare(reference, depth, scale, r);
    r.bytes_per_segment = static_cast<double>(accel.memory_bytes()) / static_cast<double>(segments);
    results.push_back(r);
  }
  // The renderer's own tracer (SceneTracer::nearest: the hit shaded, its normal, uv and
  // tangents) over the exact frusta, and with the blended crotches (docs/joints.md
  // "Crotches", crotch_tracer.h) beside them: what the fillets cost a primary ray against
  // its peer, and how far they move the depth (they fill the creases: a change, not an
  // error, measured against the exact frusta): every crotch's fillet (crotch-blend-all: a
  // build for no view in particular) and those this view needs (crotch-blend: the fillets
  // of kFilletMinPixels or more, crotch.h crotch_seen).
  auto run_scene_tracer = [&](const std::string& name, const SkinOptions& skin, bool view = true) {
    GeometryOptions geometry_options;
    geometry_options.cull = view;
    const SceneGeometry traced = build_scene_geometry(scene, skin, geometry_options);
    MethodResult r{name};
    auto trace = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const SurfaceHit h = traced.tracer->nearest(rays[i], 0, std::numeric_limits<double>::infinity());
        depth[i] = h.hit() ? h.t * glm::length(rays[i].direction) : std::numeric_limits<double>::infinity();
      }
    };
    r.rays_per_s_1 = static_cast<double>(rays.size()) / time_trace(rays.size(), 1, repeats, trace);
    r.rays_per_s_all = static_cast<double>(rays.size()) / time_trace(rays.size(), all, repeats, trace);
    compare(reference, depth, scale, r);
    r.bytes_per_segment = static_cast<double>(traced.tracer->memory_bytes()) / static_cast<double>(segments);
    std::printf("%s: %s\n", name.c_str(), traced.tracer->describe().c_str());
    results.push_back(r);
  };
  const SkinOptions blended;
  run_scene_tracer("scene-tracer", exact);
  run_scene_tracer("crotch-blend-all", blended, false);
  run_scene_tracer("crotch-blend", blended);
  {
    // What the mesh paths pay for the same fillets (GL, the polygon baseline and glTF build
    // skeleton_fillets when they load a plant; crotch_mesh.h): triangles and CPU seconds.
    const SkinnedSkeleton skin = skin_skeleton(grown->skeleton, blended);
    const double cpu_start = process_cpu_seconds();
    const TriangleMesh fillets = skeleton_fillets(grown->skeleton, skin.frusta, 1);
    const double cpu_s = process_cpu_seconds() - cpu_start;
    const Clock::time_point wall_start = Clock::now();
    (void)skeleton_fillets(grown->skeleton, skin.frusta, all);
    std::printf("fillet-mesh: %zu crotches, %zu triangles in %.3f CPU-s on one thread, %.3f s on %u\n",
                find_crotches(grown->skeleton, skin.frusta).size(), fillets.triangle_count(), cpu_s,
                seconds_since(wall_start), all);
  }
  run_embree("embree-curves", [&](RTCScene s) {
    // One vertex per joint (x, y, z, r); one index per segment (its first vertex). A
    // branch chain starts at its parent joint's position, so chains stay connected.
    const Skeleton& sk = grown->skeleton;
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                          4 * sizeof(float), sk.joints.size()));
    for (size_t j = 0; j < sk.joints.size(); ++j) {
      for (int k = 0; k < 3; ++k) v[4 * j + k] = static_cast<float>(sk.joints[j].position_m[k]);
      v[4 * j + 3] = static_cast<float>(sk.joints[j].radius_m);
    }
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                                               sizeof(unsigned), segments));
    size_t n = 0;
    for (const Chain& c : sk.chains)
      for (uint32_t j = 0; j + 1 < c.joint_count; ++j) idx[n++] = c.first_joint + j;
    rtcCommitGeometry(geom);
    rtcAttachGeometry(s, geom);
    rtcReleaseGeometry(geom);
  });
  rtcReleaseDevice(device);
  SkinnedSkeleton skinned;
  skinned.frusta = geometry.frusta;
  for (int m = 0; m <= max_level; ++m) {
    TessellateOptions o;
    o.level = m;
    const MeshTracer mesh(tessellate(skinned, o), geometry.frusta, geometry.plant_of_frustum, m);
    MethodResult r{"embree-mesh-m" + std::to_string(m)};
    auto trace = [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) {
        const SurfaceHit h = mesh.nearest(rays[i], 0, std::numeric_limits<double>::infinity());
        depth[i] = h.hit() ? h.t * glm::length(rays[i].direction) : std::numeric_limits<double>::infinity();
      }
    };
    r.rays_per_s_1 = static_cast<double>(rays.size()) / time_trace(rays.size(), 1, repeats, trace);
    r.rays_per_s_all = static_cast<double>(rays.size()) / time_trace(rays.size(), all, repeats, trace);
    compare(reference, depth, scale, r);
    r.bytes_per_segment = static_cast<double>(mesh.memory_bytes()) / static_cast<double>(segments);
    results.push_back(r);
  }

  std::printf("%-16s %14s %14s %12s %14s %12s\n", "method", "Mrays/s 1 thr", "Mrays/s all", "hit/miss",
              "depth RMS", "B/segment");
  std::string table = "method,rays_per_s_1,rays_per_s_all,miss_disagreement,depth_rms_rel,bytes_per_segment\n";
  for (const MethodResult& r : results) {
    std::printf("%-16s %14.3f %14.3f %11.4f%% %14.3g %12.0f\n", r.name.c_str(), r.rays_per_s_1 / 1e6,
                r.rays_per_s_all / 1e6, 100 * r.miss_disagreement, r.depth_rms_rel, r.bytes_per_segment);
    char line[256];
    std::snprintf(line, sizeof line, "%s,%.6g,%.6g,%.6g,%.6g,%.6g\n", r.name.c_str(), r.rays_per_s_1,
                  r.rays_per_s_all, r.miss_disagreement, r.depth_rms_rel, r.bytes_per_segment);
    table += line;
  }
  std::printf("(hit/miss and depth RMS against sylva-bvh, the analytic reference; depth RMS relative to the\n"
              " scene's bounding-box diagonal; B/segment: the structure's bytes over the skeleton's segments)\n");
  if (!csv.empty()) std::ofstream(csv) << table;
  return kOk;
}

}  // namespace sylva::cli
