// orbit_camera.cpp — see orbit_camera.h.
#include "app/studio/orbit_camera.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/util/math.h"

namespace sylva::studio {

namespace {
constexpr double kDegPerPixel = 0.3;
constexpr double kZoomPerStep = 0.85;
}  // namespace

OrbitCamera OrbitCamera::from(const Camera& camera) {
  OrbitCamera o;
  o.target = camera.target;
  const glm::dvec3 d = camera.eye - camera.target;
  o.distance = std::max(1e-6, glm::length(d));
  o.pitch_deg = std::clamp(std::asin(std::clamp(d.y / o.distance, -1.0, 1.0)) / kRadPerDeg, -89.0, 89.0);
  o.yaw_deg = std::atan2(d.x, d.z) / kRadPerDeg;
  o.fov_y_deg = camera.fov_y_deg;
  return o;
}

glm::dvec3 OrbitCamera::eye() const {
  const double yaw = yaw_deg * kRadPerDeg, pitch = pitch_deg * kRadPerDeg;
  return target + distance * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
}

Camera OrbitCamera::camera() const {
  Camera c;
  c.eye = eye();
  c.target = target;
  c.up = {0, 1, 0};
  c.fov_y_deg = fov_y_deg;
  return c;
}

void OrbitCamera::orbit(double dx_px, double dy_px) {
  yaw_deg = std::fmod(yaw_deg - dx_px * kDegPerPixel, 360.0);
  pitch_deg = std::clamp(pitch_deg + dy_px * kDegPerPixel, -89.0, 89.0);
}

void OrbitCamera::pan(double dx_px, double dy_px, double height_px) {
  const glm::dvec3 forward = glm::normalize(target - eye());
  const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = glm::cross(right, forward);
  // Metres per pixel at the target's distance.
  const double m_per_px = 2 * distance * std::tan(0.5 * fov_y_deg * kRadPerDeg) / std::max(1.0, height_px);
  target += (-dx_px * m_per_px) * right + (dy_px * m_per_px) * up;
}

void OrbitCamera::zoom(double wheel_steps) {
  distance = std::clamp(distance * std::pow(kZoomPerStep, wheel_steps), 1e-4, 1e7);
}

void OrbitCamera::frame(const glm::dvec3& lo, const glm::dvec3& hi, double width, double height) {
  const Camera c = framing_camera(lo, hi, static_cast<uint32_t>(std::max(1.0, width)),
                                  static_cast<uint32_t>(std::max(1.0, height)));
  const OrbitCamera framed = from(c);
  target = framed.target;
  distance = framed.distance;
  fov_y_deg = framed.fov_y_deg;
}

}  // namespace sylva::studio
