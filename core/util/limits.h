// limits.h — the documented ranges sylva accepts at its boundaries (docs/limits.md,
// "Numbers"): every reader and front end checks against these, so that both renderers
// only ever see numbers they can represent (Embree and the GL backend compute in float).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace sylva {

// Largest |x|, |y| or |z| of a joint, a plant's placement, the camera, and largest radius,
// in metres: far beyond any plant, far inside float's range (squares stay finite).
inline constexpr double kMaxCoordinateM = 1e12;

// Image sizes: each side, and the pixels of one image (8192 × 8192: 1 GiB of RGBA float
// for the beauty alone), and samples per pixel.
inline constexpr uint32_t kMaxImageSide = 65536;
inline constexpr uint64_t kMaxImagePixels = uint64_t{1} << 26;
inline constexpr uint32_t kMaxSamplesPerPixel = 65536;

// Why width × height × spp is outside the limits above, or nullopt.
inline std::optional<std::string> image_size_problem(uint64_t width, uint64_t height, uint64_t spp = 1) {
  if (width == 0 || height == 0 || width > kMaxImageSide || height > kMaxImageSide)
    return "the image must be from 1 to " + std::to_string(kMaxImageSide) + " pixels on each side, not " +
           std::to_string(width) + "x" + std::to_string(height);
  if (width * height > kMaxImagePixels)
    return "the image has " + std::to_string(width * height) + " pixels (" + std::to_string(width) + "x" +
           std::to_string(height) + "), more than the limit of " + std::to_string(kMaxImagePixels) +
           " (8192x8192; docs/limits.md)";
  if (spp == 0 || spp > kMaxSamplesPerPixel)
    return "samples per pixel must be from 1 to " + std::to_string(kMaxSamplesPerPixel) + ", not " +
           std::to_string(spp);
  return std::nullopt;
}

// `v` itself when its largest magnitude is ordinary, else `v` divided by it (components like
// 1e200 or 1e-200, whose squares overflow or underflow): the same direction, safe to
// normalise. The zero vector (or a non-finite one) gives nullopt.
inline std::optional<glm::dvec3> rescaled_direction(glm::dvec3 v) {
  const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  if (!(largest > 0) || !std::isfinite(largest)) return std::nullopt;
  if (largest > 1e150 || largest < 1e-150) v /= largest;
  return v;
}

// rescaled_direction, normalised: ordinary vectors go to glm::normalize as they are, so
// results on them do not change.
inline std::optional<glm::dvec3> safe_normalize(const glm::dvec3& v) {
  std::optional<glm::dvec3> r = rescaled_direction(v);
  if (r) *r = glm::normalize(*r);
  return r;
}

}  // namespace sylva
