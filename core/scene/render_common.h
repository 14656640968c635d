// render_common.h — what the CPU reference (render_cpu.cpp) and the GL renderer
// (render_gl.cpp) must share so that they cannot drift apart: the camera frame, the sample
// stream and the sun-disc sampling. The shading model and its constants: core/light/shading.h.
#pragma once

#include <optional>

#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>

#include "core/geometry/ray_frustum.h"
#include "core/scene/scene.h"
#include "core/geometry/skin.h"
#include "core/util/random.h"

namespace sylva::render_common {

// SplitMix64 (core/util/random.h), counter based: a pixel sample (CPU) or a pass (GL) draws
// the same numbers whatever thread renders it.
using SampleRng = Rng;

// The camera's orthonormal frame and the image plane's half extents at distance 1.
struct CameraFrame {
  glm::dvec3 eye, forward, right, up;
  double half_height = 1, half_width = 1;
  double width = 1, height = 1;  // pixels
};

inline CameraFrame camera_frame(const Scene& scene) {
  CameraFrame f;
  f.eye = scene.camera.eye;
  f.forward = glm::normalize(scene.camera.target - scene.camera.eye);
  f.right = glm::normalize(glm::cross(f.forward, scene.camera.up));
  f.up = glm::cross(f.right, f.forward);
  f.width = scene.width;
  f.height = scene.height;
  f.half_height = std::tan(0.5 * scene.camera.fov_y_deg * std::numbers::pi / 180);
  f.half_width = f.half_height * f.width / f.height;
  return f;
}

// The ray through continuous pixel position (x, y) of `f`'s image (y downward); the
// direction is not unit.
inline Ray frame_ray(const CameraFrame& f, double x, double y) {
  const double sx = (2 * x / f.width - 1) * f.half_width;
  const double sy = (1 - 2 * y / f.height) * f.half_height;
  return {f.eye, f.forward + sx * f.right + sy * f.up};
}

// The continuous pixel position of world point `p` in `f`'s image (y downward; frame_ray's
// inverse), and its depth along `forward`; nullopt for a point not in front of the eye.
struct FramePixel {
  double x = 0, y = 0, depth = 0;
};
inline std::optional<FramePixel> frame_pixel(const CameraFrame& f, const glm::dvec3& p) {
  const glm::dvec3 d = p - f.eye;
  const double depth = glm::dot(d, f.forward);
  if (!(depth > 0)) return std::nullopt;
  const double sx = glm::dot(d, f.right) / depth / f.half_width;
  const double sy = glm::dot(d, f.up) / depth / f.half_height;
  return FramePixel{(sx + 1) * 0.5 * f.width, (1 - sy) * 0.5 * f.height, depth};
}

// A unit direction on the sun's disc of angular radius acos(cos_alpha) around
// `sun_direction` (unit; `frame` = axis_frame(sun_direction)), uniform in solid angle
// (cos θ uniform in [cos α, 1]); two draws from `rng`.
inline glm::dvec3 sample_sun_disc(const glm::dvec3& sun_direction, double cos_alpha, const AxisFrame& frame,
                                  SampleRng& rng) {
  const double cos_t = 1 - rng.next_double() * (1 - cos_alpha);
  const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
  const double phi = 2 * std::numbers::pi * rng.next_double();
  return glm::normalize(cos_t * sun_direction + sin_t * (std::cos(phi) * frame.e0 + std::sin(phi) * frame.e1));
}

}  // namespace sylva::render_common

namespace sylva {

// The primary ray through continuous pixel position (x, y) in [0, width] × [0, height]
// (y downward); pixel (i, j)'s centre is (i + 0.5, j + 0.5). The direction is not unit.
inline Ray camera_ray(const Scene& scene, double x, double y) {
  return render_common::frame_ray(render_common::camera_frame(scene), x, y);
}

}  // namespace sylva
