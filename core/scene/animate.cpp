// animate.cpp — see animate.h. The bend profile is the slope of a uniformly loaded
// Euler–Bernoulli cantilever, w(x) ∝ x²(6L² − 4Lx + x²), whose slope w'(x) ∝
// 1 − (1 − x/L)³ once normalised to 1 at the free end.
#include "core/scene/animate.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "core/util/random.h"

namespace sylva {

namespace {

constexpr double kDegToRad = std::numbers::pi / 180;

// A uniform number in [0, 1) from a key (one SplitMix64 draw).
double uniform_from(uint64_t key) { return Rng(key).next_double(); }

// Normalised cantilever slope at relative height x (clamped to [0, 1]).
double cantilever_slope(double x) {
  const double rest = 1 - std::clamp(x, 0.0, 1.0);
  return 1 - rest * rest * rest;
}

// R(θ)·d − d for the rotation by θ about the unit axis a (Rodrigues: R d = d + sin θ
// a×d + (1 − cos θ) a×(a×d)), with 1 − cos θ as 2 sin²(θ/2) so that small angles keep
// their precision. Exactly zero for θ = 0.
glm::dvec3 rotation_offset(const glm::dvec3& axis, double angle_rad, const glm::dvec3& d) {
  const glm::dvec3 across = glm::cross(axis, d);
  const double half_sin = std::sin(0.5 * angle_rad);
  return std::sin(angle_rad) * across + (2 * half_sin * half_sin) * glm::cross(axis, across);
}

glm::dvec3 position_of(const Joint& j) { return {j.position_m[0], j.position_m[1], j.position_m[2]}; }

}  // namespace

double looping_frequency_hz(double frequency_hz, double period_s) {
  if (!(period_s > 0) || !(frequency_hz > 0)) return frequency_hz;
  return std::max(1.0, std::round(frequency_hz * period_s)) / period_s;
}

std::optional<glm::dvec3> sway_axis(const SwayParameters& parameters) {
  const glm::dvec3 wind(parameters.wind_direction.x, 0, parameters.wind_direction.z);
  const double wind_length = glm::length(wind);
  if (!(wind_length > 0)) return std::nullopt;
  return glm::cross(glm::dvec3(0, 1, 0), wind / wind_length);
}

std::vector<double> sway_joint_angles(const Skeleton& rest, double t_s, const SwayParameters& parameters) {
  std::vector<double> angle(rest.joints.size(), 0.0);
  if (rest.joints.empty()) return angle;
  double base_y = rest.joints.front().position_m[1], top_y = base_y;
  for (const Joint& j : rest.joints) {
    base_y = std::min(base_y, j.position_m[1]);
    top_y = std::max(top_y, j.position_m[1]);
  }
  const double height = top_y - base_y;
  const double period_s = parameters.loop_period_s;
  const double bend_rad = parameters.amplitude_deg * kDegToRad *
                          std::sin(2 * std::numbers::pi * looping_frequency_hz(parameters.frequency_hz, period_s) * t_s);
  // Each chain's flutter, its parent's included (parents come first).
  std::vector<double> flutter_rad(rest.chains.size(), 0.0);
  for (size_t c = 0; c < rest.chains.size(); ++c) {
    const Chain& chain = rest.chains[c];
    if (chain.parent) {
      assert(chain.parent->chain < c && "parents come before their children (validate_skeleton)");
      const double frequency_hz = looping_frequency_hz(
          parameters.branch_frequency_hz * (0.75 + 0.5 * chain_flutter_draw(parameters.seed, c)), period_s);
      flutter_rad[c] = flutter_rad[chain.parent->chain] + parameters.branch_amplitude_deg * kDegToRad *
                                                              std::sin(2 * std::numbers::pi * frequency_hz * t_s);
    }
    for (uint32_t i = chain.first_joint; i < chain.first_joint + chain.joint_count; ++i) {
      const Joint& j = rest.joints[i];
      angle[i] = (height > 0 ? bend_rad * cantilever_slope((j.position_m[1] - base_y) / height) : 0.0) + flutter_rad[c];
    }
  }
  return angle;
}

Skeleton sway_skeleton(const Skeleton& rest, double t_s, const SwayParameters& parameters) {
  Skeleton out = rest;
  const std::optional<glm::dvec3> axis = sway_axis(parameters);
  if (!axis || rest.joints.empty()) return out;
  const std::vector<double> angle = sway_joint_angles(rest, t_s, parameters);

  // Displacement of every joint from its rest position; accumulated from the base out.
  std::vector<glm::dvec3> moved(rest.joints.size(), glm::dvec3(0));
  for (size_t c = 0; c < rest.chains.size(); ++c) {
    const Chain& chain = rest.chains[c];
    if (chain.joint_count == 0) continue;
    const uint32_t first = chain.first_joint;
    if (chain.parent) {
      // The first joint hangs from the parent joint: it follows that joint's motion, its
      // offset from it turned by the angle there.
      const uint32_t anchor = rest.chains[chain.parent->chain].first_joint + chain.parent->joint;
      const glm::dvec3 offset = position_of(rest.joints[first]) - position_of(rest.joints[anchor]);
      moved[first] = moved[anchor] + rotation_offset(*axis, angle[anchor], offset);
    }
    for (uint32_t i = first; i + 1 < first + chain.joint_count; ++i) {
      const glm::dvec3 segment = position_of(rest.joints[i + 1]) - position_of(rest.joints[i]);
      moved[i + 1] = moved[i] + rotation_offset(*axis, angle[i], segment);
    }
  }
  for (size_t i = 0; i < out.joints.size(); ++i)
    for (int k = 0; k < 3; ++k) out.joints[i].position_m[k] += moved[i][k];
  // A leaf moves with its joint (docs/spec/skeleton.md "Leaves"): rigidly, as the segment that
  // leaves that joint turns, by the angle there; a leaf on no joint stays.
  for (Leaf& leaf : out.leaves) {
    if (!leaf.joint) continue;
    const uint32_t anchor = rest.chains[leaf.joint->chain].first_joint + leaf.joint->joint;
    for (auto& v : leaf.vertices_m) {
      const glm::dvec3 offset = glm::dvec3(v[0], v[1], v[2]) - position_of(rest.joints[anchor]);
      const glm::dvec3 d = moved[anchor] + rotation_offset(*axis, angle[anchor], offset);
      for (int k = 0; k < 3; ++k) v[static_cast<size_t>(k)] += d[k];
    }
  }
  return out;
}

double chain_flutter_draw(uint64_t seed, size_t chain) { return uniform_from(mix_pair(seed, chain)); }

SwayParameters plant_sway_parameters(const SwayParameters& parameters, size_t p) {
  SwayParameters own = parameters;
  own.seed = mix_pair(parameters.seed, 0x5A11'0000ull + p);
  own.frequency_hz *= 0.85 + 0.3 * uniform_from(mix64(own.seed));
  return own;
}

void sway_scene_plants(Scene& scene, const std::vector<Skeleton>& rest, double t_s,
                       const SwayParameters& parameters) {
  assert(rest.size() == scene.plants.size() && "one rest skeleton per plant");
  for (size_t p = 0; p < scene.plants.size(); ++p)
    scene.plants[p].skeleton = sway_skeleton(rest[p], t_s, plant_sway_parameters(parameters, p));
}

SwayParameters sway_parameters_of(const SceneAnimation& animation) {
  SwayParameters p;
  p.wind_direction = animation.wind;
  p.amplitude_deg = animation.amplitude_deg;
  p.frequency_hz = animation.frequency_hz;
  p.branch_amplitude_deg = animation.branch_amplitude_deg;
  p.branch_frequency_hz = animation.branch_frequency_hz;
  p.seed = animation.seed;
  return p;
}

double animation_frame_time_s(const SceneAnimation& animation, uint64_t frame) {
  return static_cast<double>(frame) / animation.fps;
}

}  // namespace sylva
