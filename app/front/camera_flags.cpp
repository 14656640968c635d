// camera_flags.cpp — see camera_flags.h.
#include "app/front/camera_flags.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <glm/geometric.hpp>

#include "app/front/args.h"

namespace sylva::cli {

namespace {

// One finite decimal number filling `text` (a leading '+' allowed, as -D takes).
std::optional<double> finite_number(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

glm::dvec3 parse_point_flag(const std::string& flag, const std::string& value) {
  const std::string expected = flag + " " + value + ": expected X,Y,Z: three finite numbers in metres, e.g. 6,3,6";
  glm::dvec3 p{};
  size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = value.find(',', start);
    if ((k < 2) != (comma != std::string::npos)) throw UsageError{expected};
    const size_t end = comma == std::string::npos ? value.size() : comma;
    const std::optional<double> v = finite_number(std::string_view(value).substr(start, end - start));
    if (!v) throw UsageError{expected};
    p[k] = *v;
    start = end + 1;
  }
  return p;
}

double parse_fov_flag(const std::string& value) {
  const std::optional<double> v = finite_number(value);
  if (!v || !(*v > 0 && *v < 180))
    throw UsageError{"--fov " + value + ": expected the vertical field of view in degrees, a number between 0 and 180"};
  return *v;
}

void apply_camera_flags(const CameraFlags& flags, Camera& camera) {
  if (!flags.any()) return;  // the input's camera, as it was
  if (flags.eye) camera.eye = *flags.eye;
  if (flags.target) camera.target = *flags.target;
  if (flags.fov_y_deg) camera.fov_y_deg = *flags.fov_y_deg;
  // The one camera check (scene.h camera_problem), as a scene file's camera has it.
  const std::optional<std::string> problem = camera_problem(camera);
  if (!problem) return;
  if (problem->starts_with("eye coordinates")) throw UsageError{"--eye: the " + *problem};
  if (problem->starts_with("target coordinates")) throw UsageError{"--target: the " + *problem};
  if (problem->starts_with("eye and target"))
    throw UsageError{"--eye and --target: the camera's eye and target must differ"};
  if (problem->starts_with("up must not be parallel"))
    throw UsageError{"--eye and --target: the view must not be straight along the camera's up (a scene's "
                     "camera.up, else +Y): move the eye or the target sideways a little"};
  throw UsageError{"--eye, --target, --fov: the camera's " + *problem};
}

}  // namespace sylva::cli
