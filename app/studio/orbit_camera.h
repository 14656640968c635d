// orbit_camera.h — the viewport's camera as a user moves it (docs/spec/studio.md "Viewport"):
// orbit (left drag) about a target, pan (middle drag or Shift+left) in the view plane,
// zoom (wheel) toward the target, frame (F) a box. Stored as target, distance, yaw and
// pitch so orbiting never rolls; converted to the scene's pinhole Camera (scene.h:
// metres, Y up, degrees) for rendering.
#pragma once

#include <glm/vec3.hpp>

#include "core/scene/scene.h"

namespace sylva::studio {

struct OrbitCamera {
  glm::dvec3 target{0, 2, 0};
  double distance = 8;      // metres from the target to the eye, > 0
  double yaw_deg = 45;      // azimuth of the eye about +Y, from +Z toward +X
  double pitch_deg = 15;    // elevation of the eye above the target's horizon, (-89, 89)
  double fov_y_deg = 40;

  // The orbit camera whose Camera() is `camera` (up taken as +Y).
  static OrbitCamera from(const Camera& camera);
  Camera camera() const;
  glm::dvec3 eye() const;

  // Pixel deltas of a drag in a viewport `height_px` tall.
  void orbit(double dx_px, double dy_px);                     // 0.3 degrees per pixel
  void pan(double dx_px, double dy_px, double height_px);     // the target follows the cursor
  void zoom(double wheel_steps);                              // 15% closer per step
  // Frames the box [lo, hi] for an image of width × height (framing_camera's view
  // direction is kept: only target and distance change).
  void frame(const glm::dvec3& lo, const glm::dvec3& hi, double width, double height);
};

}  // namespace sylva::studio
