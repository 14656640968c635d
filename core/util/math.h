// math.h — the constants every stage uses, defined once.
#pragma once

#include <numbers>

namespace sylva {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kRadPerDeg = kPi / 180;  // degrees → radians

}  // namespace sylva
