// plant_mesh.cpp — tessellate, then displace as deep as the relief shell is thick.
#include "core/geometry/plant_mesh.h"

#include <algorithm>
#include <chrono>
#include <glm/geometric.hpp>
#include <span>

#include "core/geometry/relief.h"
#include "core/util/clock.h"

namespace sylva {


namespace {

// plant_mesh's displacement scale per vertex.
std::vector<double> displacement_scale(const TriangleMesh& mesh, std::span<const Frustum> frusta, double depth_m,
                                       double max_depth_per_radius, std::span<const Crotch> crotches) {
  std::vector<double> scale(mesh.positions.size(), 1.0);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const FrustumShape& shape = frusta[mesh.triangle_frustum[t]].shape;
    const ShellDepths d = relief_shell_depths(shape, depth_m, max_depth_per_radius);
    if (d.lower_m == depth_m && d.upper_m == depth_m) continue;  // thick enough: the full depth
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.indices[3 * t + c];
      const double y = std::clamp(glm::dot(mesh.positions[v] - shape.base, shape.axis) / shape.length, 0.0, 1.0);
      scale[v] = (d.lower_m + (d.upper_m - d.lower_m) * y) / depth_m;
    }
  }
  // The bark covers the wood only (material 0, materials.h): other materials keep their
  // smooth surface, and a vertex shared with the wood stays where both put it.
  for (size_t t = 0; t < mesh.triangle_count(); ++t)
    if (frusta[mesh.triangle_frustum[t]].material != 0)
      for (int c = 0; c < 3; ++c) scale[mesh.indices[3 * t + c]] = 0.0;
  // Into the blended crotches' fillets, the least fade of a vertex's frusta.
  if (!crotches.empty()) {
    const CrotchesOfFrusta of_frustum = crotches_of_frusta(crotches, frusta.size());
    std::vector<double> fade(mesh.positions.size(), 1.0);
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      const std::span<const uint32_t> which = of_frustum.of(mesh.triangle_frustum[t]);
      if (which.empty()) continue;
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = mesh.indices[3 * t + c];
        fade[v] = std::min(fade[v], relief_fade_at(crotches, which, frusta, mesh.positions[v]));
      }
    }
    for (size_t v = 0; v < scale.size(); ++v) scale[v] *= fade[v];
  }
  return scale;
}

}  // namespace

TriangleMesh plant_mesh(const SkinnedSkeleton& skinned, const TessellateOptions& tessellation, const HeightFn& height,
                        double relief_depth_m, double max_depth_per_radius, double* tessellate_s, double* displace_s,
                        std::span<const Crotch> crotches) {
  Clock::time_point start = Clock::now();
  TriangleMesh mesh = tessellate(skinned, tessellation);
  *tessellate_s += seconds_since(start);
  if (height) {
    start = Clock::now();
    mesh = displace(mesh, height, displacement_scale(mesh, skinned.frusta, relief_depth_m, max_depth_per_radius, crotches));
    *displace_s += seconds_since(start);
  }
  return mesh;
}

}  // namespace sylva
