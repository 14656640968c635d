// color.cpp — the sRGB transfer function (IEC 61966-2-1).
#include "core/util/color.h"

#include <algorithm>
#include <cmath>

namespace sylva {

float linear_to_srgb(float linear) {
  float x = std::clamp(linear, 0.0f, 1.0f);
  if (!(x == x)) x = 0;  // NaN
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1 / 2.4f) - 0.055f;
}

uint8_t linear_to_srgb8(float linear) {
  return static_cast<uint8_t>(std::lround(linear_to_srgb(linear) * 255.0f));
}

double srgb_to_linear(double encoded) {
  const double c = std::clamp(encoded, 0.0, 1.0);
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

}  // namespace sylva
