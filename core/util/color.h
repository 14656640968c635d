// color.h — the sRGB transfer function both ways (IEC 61966-2-1), shared by image output
// (linear → encoded), texture lookups (encoded → linear, after filtering) and plots.
#pragma once

#include <cstdint>

namespace sylva {

// The encoded value of a linear one, clamped to [0, 1] (NaN gives 0).
float linear_to_srgb(float linear);

// The same as an 8-bit code: linear_to_srgb scaled to 0..255, rounded to nearest.
uint8_t linear_to_srgb8(float linear);

// The linear value of an encoded one in [0, 1] (clamped).
double srgb_to_linear(double encoded);

}  // namespace sylva
