// camera_flags.h — `sylva render --eye X,Y,Z --target X,Y,Z --fov DEG` (docs/spec/cli.md): a camera
// given on the command line, for a grammar or skeleton (whose default scene frames the
// plant, docs/spec/scene.md) and for a scene (overriding its `camera` key).
//
// Units and frame: world metres, Y up (docs/spec/grammar.md's frame, as a scene's camera); --fov is
// the full vertical field of view in degrees, as the scene key `fov_y_deg`. A flag left
// out keeps that part of the camera the input gives (so --eye alone moves the eye and
// still looks at the framed plant). Every error is a UsageError (exit 2) naming the flag.
#pragma once

#include <glm/vec3.hpp>
#include <optional>
#include <string>

#include "core/scene/scene.h"

namespace sylva::cli {

struct CameraFlags {
  std::optional<glm::dvec3> eye, target;  // --eye, --target
  std::optional<double> fov_y_deg;        // --fov
  bool any() const { return eye || target || fov_y_deg; }
};

// --eye / --target: "X,Y,Z", three finite decimal numbers and nothing else.
glm::dvec3 parse_point_flag(const std::string& flag, const std::string& value);

// --fov: a number of degrees strictly between 0 and 180.
double parse_fov_flag(const std::string& value);

// Sets the parts of `camera` the flags give. The camera must then be one a scene file
// could hold (scene.cpp read_camera): eye and target distinct, the view not along `up`;
// otherwise a UsageError saying which flags to change.
void apply_camera_flags(const CameraFlags& flags, Camera& camera);

}  // namespace sylva::cli
