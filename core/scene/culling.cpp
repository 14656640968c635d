// culling.cpp — conservative view and shadow culling of plants (see culling.h).
#include "core/scene/culling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

#include "core/geometry/leaf_mesh.h"
#include "core/scene/render_common.h"
#include "core/util/math.h"

namespace sylva {

namespace {


bool corners_outside(const Plane& plane, const std::array<glm::dvec3, 8>& c) {
  for (const glm::dvec3& p : c)
    if (!(glm::dot(plane.normal, p) < plane.offset)) return false;
  return true;
}

bool sun_is_on(const Sun& sun) { return sun.radiance.x > 0 || sun.radiance.y > 0 || sun.radiance.z > 0; }

}  // namespace

ViewFrustum view_frustum(const Scene& scene) {
  const double w = scene.width, h = scene.height;
  // The rays the renderer traces through the image's corners and centre.
  const glm::dvec3 eye = camera_ray(scene, 0, 0).origin;
  const glm::dvec3 corner[4] = {camera_ray(scene, 0, 0).direction, camera_ray(scene, w, 0).direction,
                                camera_ray(scene, w, h).direction, camera_ray(scene, 0, h).direction};
  const glm::dvec3 centre = camera_ray(scene, 0.5 * w, 0.5 * h).direction;
  auto side = [&](const glm::dvec3& a, const glm::dvec3& b) {
    glm::dvec3 n = glm::normalize(glm::cross(a, b));
    if (glm::dot(n, centre) < 0) n = -n;
    return Plane{n, glm::dot(n, eye)};
  };
  ViewFrustum v;
  v.planes[0] = side(corner[0], corner[3]);  // left
  v.planes[1] = side(corner[1], corner[2]);  // right
  v.planes[2] = side(corner[2], corner[3]);  // bottom
  v.planes[3] = side(corner[0], corner[1]);  // top
  const glm::dvec3 forward = glm::normalize(centre);
  v.planes[4] = Plane{forward, glm::dot(forward, eye)};  // near: through the eye
  return v;
}

double pixels_per_radian(const Scene& scene) {
  const double w = scene.width, h = scene.height;
  const double focal = 0.5 * h / std::tan(0.5 * scene.camera.fov_y_deg * kRadPerDeg);
  return focal + 0.25 * (w * w + h * h) / focal;  // f·(1 + tan²θ), tan θ = half-diagonal / f
}

Aabb plant_box(const Skeleton& placed, const SkinOptions& skin, double relief_m) {
  const double inf = std::numeric_limits<double>::infinity();
  Aabb box{glm::dvec3(inf), glm::dvec3(-inf)};
  if (placed.joints.empty() && placed.leaves.empty()) return Aabb{};
  const double tilt = skin.max_tilt_deg * kRadPerDeg;
  const double knuckle = 1 / std::cos(std::numbers::pi / (2.0 * std::max(2, skin.knuckle_frusta)));
  // Per joint: the largest reach of a cut through it, in joint radii.
  std::vector<double> reach(placed.joints.size(), std::max(1.0, knuckle));
  auto position = [&](uint32_t j) {
    const auto& p = placed.joints[j].position_m;
    return glm::dvec3(p[0], p[1], p[2]);
  };
  for (const Chain& chain : placed.chains) {
    uint32_t previous = chain.first_joint;
    for (uint32_t k = 1; k < chain.joint_count; ++k) {
      const uint32_t j = chain.first_joint + k;
      const double length = glm::length(position(j) - position(previous));
      if (length == 0) continue;  // skinning skips it too
      const double slope = std::abs(placed.joints[j].radius_m - placed.joints[previous].radius_m) / length;
      const double d = std::max(kMinCrossingDenominator, std::cos(tilt) - slope * std::sin(tilt));
      reach[previous] = std::max(reach[previous], 1 / d);
      reach[j] = std::max(reach[j], 1 / d);
      previous = j;
    }
  }
  for (size_t j = 0; j < placed.joints.size(); ++j) {
    const glm::dvec3 p = position(static_cast<uint32_t>(j));
    const double pad = placed.joints[j].radius_m * reach[j];
    box.lo = glm::min(box.lo, p - glm::dvec3(pad));
    box.hi = glm::max(box.hi, p + glm::dvec3(pad));
  }
  grow(box, leaf_bounds(placed));  // leaves are drawn too (empty without leaves)
  // The relief, and a little more than the rounding of the arithmetic above.
  const double margin = relief_m + 1e-9 * std::max({1.0, glm::length(box.lo), glm::length(box.hi)});
  box.lo -= glm::dvec3(margin);
  box.hi += glm::dvec3(margin);
  return box;
}

std::optional<Aabb> shadow_box(const Scene& scene, const Aabb& box) {
  const Sun& sun = scene.sun;
  if (!sun_is_on(sun)) return box;
  const glm::dvec3 l = glm::normalize(sun.direction);
  const double alpha = std::max(0.0, sun.angular_radius_deg) * kRadPerDeg;
  const double elevation = std::asin(std::clamp(l.y, -1.0, 1.0));
  if (elevation - alpha <= 0) return std::nullopt;  // the disc touches the horizon
  const double y_min = std::sin(elevation - alpha), y_max = std::sin(std::min(elevation + alpha, std::numbers::pi / 2));
  const double horizontal = std::hypot(l.x, l.z);
  // Horizontal spread per metre of height between shadows cast along l and along any
  // direction within α of it (|l'_xz − l_xz| <= 2 sin(α/2), 1/l'_y within [1/y_max, 1/y_min]).
  const double spread = 2 * std::sin(0.5 * alpha) / y_min +
                        horizontal * std::max(1 / y_min - 1 / l.y, 1 / l.y - 1 / y_max);
  const double ground = scene.ground.height;
  Aabb out = box;
  for (const glm::dvec3& c : corners(box)) {
    const double height = c.y - ground;
    if (height <= 0) continue;  // at or under the ground: no shadow below it
    const glm::dvec3 landing = c - (height / l.y) * l;
    const glm::dvec3 pad(height * spread, 0, height * spread);
    out.lo = glm::min(out.lo, landing - pad);
    out.hi = glm::max(out.hi, landing + pad);
  }
  return out;
}

bool outside_view(const ViewFrustum& view, const Aabb& box) {
  const auto c = corners(box);
  for (const Plane& plane : view.planes)
    if (corners_outside(plane, c)) return true;
  return false;
}

bool plant_is_culled(const Scene& scene, const ViewFrustum& view, const Aabb& box) {
  if (!outside_view(view, box)) return false;
  const std::optional<Aabb> shadow = shadow_box(scene, box);
  if (shadow) return outside_view(view, *shadow);
  // Shadows without end: the infinite sweep along −l' for every l' of the disc.
  const glm::dvec3 l = glm::normalize(scene.sun.direction);
  const double sin_alpha = std::sin(std::max(0.0, scene.sun.angular_radius_deg) * kRadPerDeg);
  const auto c = corners(box);
  for (const Plane& plane : view.planes)
    if (corners_outside(plane, c) && glm::dot(plane.normal, -l) <= -sin_alpha) return true;
  return false;
}

}  // namespace sylva
