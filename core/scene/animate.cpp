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

Skeleton sway_skeleton(const Skeleton& rest, double t_s, const SwayParameters& parameters) {
  Skeleton out = rest;
  const glm::dvec3 wind(parameters.wind_direction.x, 0, parameters.wind_direction.z);
  const double wind_length = glm::length(wind);
  if (!(wind_length > 0) || rest.joints.empty()) return out;
  // up × wind: rotating +Y about it by a positive angle tips it toward the wind.
  const glm::dvec3 axis = glm::cross(glm::dvec3(0, 1, 0), wind / wind_length);

  double base_y = rest.joints.front().position_m[1], top_y = base_y;
  for (const Joint& j : rest.joints) {
    base_y = std::min(base_y, j.position_m[1]);
    top_y = std::max(top_y, j.position_m[1]);
  }
  const double height = top_y - base_y;
  const double bend_rad =
      parameters.amplitude_deg * kDegToRad * std::sin(2 * std::numbers::pi * parameters.frequency_hz * t_s);
  auto bend_at = [&](const Joint& j) {
    return height > 0 ? bend_rad * cantilever_slope((j.position_m[1] - base_y) / height) : 0.0;
  };

  // Each chain's flutter, its parent's included (parents come first).
  std::vector<double> flutter_rad(rest.chains.size(), 0.0);
  // Displacement of every joint from its rest position; accumulated from the base out.
  std::vector<glm::dvec3> moved(rest.joints.size(), glm::dvec3(0));
  for (size_t c = 0; c < rest.chains.size(); ++c) {
    const Chain& chain = rest.chains[c];
    if (chain.joint_count == 0) continue;
    const uint32_t first = chain.first_joint;
    if (chain.parent) {
      const ChainParent& parent = *chain.parent;
      assert(parent.chain < c && "parents come before their children (validate_skeleton)");
      const uint64_t key = mix_pair(parameters.seed, c);
      const double frequency_hz = parameters.branch_frequency_hz * (0.75 + 0.5 * uniform_from(key));
      flutter_rad[c] = flutter_rad[parent.chain] + parameters.branch_amplitude_deg * kDegToRad *
                                                       std::sin(2 * std::numbers::pi * frequency_hz * t_s);
      // The first joint hangs from the parent joint: it follows that joint's motion, its
      // offset from it turned by the angle there.
      const uint32_t anchor = rest.chains[parent.chain].first_joint + parent.joint;
      const double angle = bend_at(rest.joints[anchor]) + flutter_rad[parent.chain];
      const glm::dvec3 offset = position_of(rest.joints[first]) - position_of(rest.joints[anchor]);
      moved[first] = moved[anchor] + rotation_offset(axis, angle, offset);
    }
    for (uint32_t i = first; i + 1 < first + chain.joint_count; ++i) {
      const double angle = bend_at(rest.joints[i]) + flutter_rad[c];
      const glm::dvec3 segment = position_of(rest.joints[i + 1]) - position_of(rest.joints[i]);
      moved[i + 1] = moved[i] + rotation_offset(axis, angle, segment);
    }
  }
  for (size_t i = 0; i < out.joints.size(); ++i)
    for (int k = 0; k < 3; ++k) out.joints[i].position_m[k] += moved[i][k];
  // A leaf moves with its joint (docs/spec/skeleton.md "Leaves"): rigidly, as the segment that
  // leaves that joint turns, by the angle there; a leaf on no joint stays.
  for (Leaf& leaf : out.leaves) {
    if (!leaf.joint) continue;
    const uint32_t anchor = rest.chains[leaf.joint->chain].first_joint + leaf.joint->joint;
    const double angle = bend_at(rest.joints[anchor]) + flutter_rad[leaf.joint->chain];
    for (auto& v : leaf.vertices_m) {
      const glm::dvec3 offset = glm::dvec3(v[0], v[1], v[2]) - position_of(rest.joints[anchor]);
      const glm::dvec3 d = moved[anchor] + rotation_offset(axis, angle, offset);
      for (int k = 0; k < 3; ++k) v[static_cast<size_t>(k)] += d[k];
    }
  }
  return out;
}

void sway_scene_plants(Scene& scene, const std::vector<Skeleton>& rest, double t_s,
                       const SwayParameters& parameters) {
  assert(rest.size() == scene.plants.size() && "one rest skeleton per plant");
  for (size_t p = 0; p < scene.plants.size(); ++p) {
    SwayParameters own = parameters;
    own.seed = mix_pair(parameters.seed, 0x5A11'0000ull + p);
    own.frequency_hz *= 0.85 + 0.3 * uniform_from(mix64(own.seed));
    scene.plants[p].skeleton = sway_skeleton(rest[p], t_s, own);
  }
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
