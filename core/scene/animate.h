// animate.h — skeletons swaying in the wind: the paper's dancing cacti (Bhagvat et al. 2009, sec. 4
// and fig. 8), where every frame moves the joints and only the segment records are sent
// to the GPU again (GlRenderer::update_plants).
//
// The motion (deterministic: a pure function of the rest skeleton, t and the parameters):
//   - Bend. A plant bends away from the wind like a uniformly loaded cantilever fixed at
//     its base (Euler–Bernoulli): the slope at height h is θ(h) = A·(1 − (1 − h/H)³),
//     h measured from the lowest joint, H the plant's height, A = amplitude_deg, and the
//     load oscillates as sin(2π·frequency_hz·t) (the first mode, no damping).
//   - Flutter. Every lateral chain (one with a parent) also swings about its attachment
//     by branch_amplitude_deg·sin(2π·f_c·t), f_c drawn per chain in [0.75, 1.25]×
//     branch_frequency_hz from `seed`; a chain carries its parent's flutter with it.
//   - Both are rotations about one horizontal axis, up × wind (the wind's horizontal
//     part), so every segment turns rigidly: a segment from joint i to i+1 keeps its
//     length and is rotated by the angle at joint i (bend at i's rest height plus its
//     chain's flutter). Joints are placed from the base outwards, each chain's first
//     joint moving with the parent joint it hangs from (one that coincides with that
//     joint at rest still coincides), root chains keep their first joint.
//
// Leaves (docs/spec/skeleton.md): each turns rigidly with the joint it hangs from, by that joint's
// angle (as the segment leaving the joint does), and follows its motion; a leaf on no
// joint stays where it is.
// What stays: the joint, chain and leaf arrays' sizes and order, parents, radii, materials and
// the source record (topology unchanged, so the skinning's frustum count changes only
// where a joint's bend crosses the splitting threshold of skin.h). At t = 0, with both
// amplitudes 0, or with a wind that has no horizontal part, the result equals the rest
// skeleton bit for bit (positions are moved by accumulated displacements that are
// exactly zero then). Units: metres, seconds, degrees and hertz as the names say; the
// skeleton's frame (Y up).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene/scene.h"
#include "core/geometry/skeleton.h"

namespace sylva {

// How a skeleton sways (defaults: a light breeze on a plant a few metres tall).
struct SwayParameters {
  glm::dvec3 wind_direction{1, 0, 0};  // where the wind blows to; only the horizontal
                                       // (x, z) part counts, its length does not
  double amplitude_deg = 4;            // A: bend of the plant's top at the sway's extreme
  double frequency_hz = 0.4;           // the plant's sway
  double branch_amplitude_deg = 3;     // each lateral chain's swing about its attachment
  double branch_frequency_hz = 1.1;    // mean flutter frequency of the lateral chains
  uint64_t seed = 0;                   // draws each chain's flutter frequency
  double loop_period_s = 0;            // > 0: every frequency (the sway's and each chain's
                                       // flutter) is rounded to the nearest positive
                                       // multiple of 1/loop_period_s (looping_frequency_hz),
                                       // so the motion repeats exactly after it (the glTF
                                       // wind clip, docs/gltf.md "Wind clip"); 0: as given
};

// `frequency_hz` rounded to a whole number of cycles per `period_s`: n/period_s with
// n = round(frequency_hz·period_s), at least 1 for a frequency > 0; 0 stays 0. period_s
// not > 0 returns frequency_hz unchanged.
double looping_frequency_hz(double frequency_hz, double period_s);

// The horizontal axis every sway turns about: up × the wind's unit horizontal part
// (rotating +Y about it by a positive angle tips it toward the wind); nullopt when the
// wind has no horizontal part (nothing moves).
std::optional<glm::dvec3> sway_axis(const SwayParameters& parameters);

// The angle (radians, about sway_axis) by which the segment leaving each joint of `rest`
// turns at t_s: the bend at the joint's rest height plus its chain's flutter (its
// parent chains' included). One per joint, all 0 at t = 0. sway_skeleton moves every
// joint and leaf with these angles; the glTF wind clip poses its rig with them.
std::vector<double> sway_joint_angles(const Skeleton& rest, double t_s, const SwayParameters& parameters);

// The rest skeleton `rest` (validate_skeleton holds) swayed to time t_s seconds.
Skeleton sway_skeleton(const Skeleton& rest, double t_s, const SwayParameters& parameters);

// The draw u in [0, 1) that sets chain `chain`'s flutter frequency,
// branch_frequency_hz · (0.75 + 0.5·u), for a sway with seed `seed` (the glTF wind data's
// phase, docs/gltf.md "Wind data for shaders").
double chain_flutter_draw(uint64_t seed, size_t chain);

// Plant p's own sway in a scene: `parameters` with its own seed (from parameters.seed and
// p) and its sway frequency scaled by a factor in [0.85, 1.15] drawn from that seed.
SwayParameters plant_sway_parameters(const SwayParameters& parameters, size_t p);

// Sets every plant's skeleton of `scene` to its rest skeleton rest[p] swayed to t_s, the
// plants out of step: plant p uses plant_sway_parameters(parameters, p).
// Precondition: rest.size() == scene.plants.size().
void sway_scene_plants(Scene& scene, const std::vector<Skeleton>& rest, double t_s,
                       const SwayParameters& parameters);

// The sway of a scene's `animation` key (docs/animation.md): its wind, amplitudes,
// frequencies and seed.
SwayParameters sway_parameters_of(const SceneAnimation& animation);

// The time of frame `frame` of an animation: frame / fps seconds.
double animation_frame_time_s(const SceneAnimation& animation, uint64_t frame);

}  // namespace sylva
