// gltf_rig.h — the wind rig of a glTF export (docs/gltf.md "Rig and wind clip"): a coarse
// joint tree along the skeleton's first branch orders, the skin weights of any point of
// the plant, and the sway of core/scene/animate.h posed on the joints. Pure geometry: the
// glTF encoding (skin, JOINTS_0/WEIGHTS_0, inverseBindMatrices, the clip) is
// gltf_writer.cpp's.
//
// The joints (build_rig):
//   - joint 0, the root, sits at the plant's origin and never turns;
//   - a rigged chain (a skeleton chain with at least one segment) has a joint on its
//     local joints 0, k, 2k, … below its last joint (the tip has no segment leaving it),
//     each joint the parent of the next; its first joint hangs from the last joint of
//     the nearest rigged ancestor chain at or below the joint it grows from (from the
//     root for a root chain);
//   - which chains and which k: the largest branch order L ≤ max_order for which some k
//     fits every chain of order ≤ L into max_joints joints (root included) and
//     max_depth levels, with the smallest such k; then, with that k, the chains of
//     order L + 1 (if L < max_order) in decreasing order of their subtree's length
//     (their own segments and all their descendants'), each while it still fits.
//     Parents come before children. An error when not even the root chains fit.
// The weights (rig_weights): a point on a rigged chain at arc length s from the chain's
// first joint is blended linearly between the two rig joints of that chain that bracket s
// (one joint past the last); a point on an unrigged chain, or a leaf, rides rigidly as its
// attachment point on the nearest rigged ancestor does (the same weights); a leaf on no
// joint, or a plant with no rigged chain, follows the root. Never more than two
// influences, weights ≥ 0 summing to 1.
// The pose (pose_rig): every joint's world rotation turns about the sway axis by the
// angle of the segment leaving its skeleton joint (sway_joint_angles; the root 0), its
// position follows its parent's: P_j = P_parent + R(φ_parent)·(p_j − p_parent). With a
// joint on every joint of every chain this is sway_skeleton exactly; coarser rigs differ
// by the angle changes within k internodes (docs/gltf.md states the measured error).
// Units and frames: metres, radians, the plant's own frame (Y up), as the skeleton.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/geometry/skeleton.h"
#include "core/util/diagnostic.h"

namespace sylva {

inline constexpr uint32_t kDefaultRigJoints = 128;
inline constexpr uint32_t kMaxRigJoints = 1024;  // `--max-joints` at most (docs/limits.md)
inline constexpr uint32_t kMaxRigDepth = 512;    // Blender 3.4's importer fails near 990 levels
inline constexpr uint32_t kNoRigJoint = UINT32_MAX;

struct RigOptions {
  uint32_t max_joints = kDefaultRigJoints;  // 1 .. kMaxRigJoints, the root counted
  uint32_t max_depth = kMaxRigDepth;        // levels below the root
  uint32_t max_order = 2;                   // branch orders rigged at most (0: root chains)
};

struct RigJoint {
  uint32_t skeleton_joint = kNoRigJoint;  // index into Skeleton::joints; none for the root
  uint32_t chain = kNoRigJoint;           // its skeleton chain; none for the root
  uint32_t parent = kNoRigJoint;          // rig joint index, < this one's; none for the root
  glm::dvec3 position_m{0};               // rest position (the plant's frame)
  uint32_t depth = 0;                     // levels below the root
};

struct Rig {
  std::vector<RigJoint> joints;  // joints[0] is the root; parents before children
  uint32_t full_order = 0;       // L: every chain of order ≤ L is rigged
  uint32_t step = 1;             // k: a joint every k internodes along a rigged chain
  uint32_t rigged_chains = 0;
  // Per skeleton chain: its rig joints in order along it (empty: unrigged).
  std::vector<std::vector<uint32_t>> chain_joints;
  // Per skeleton joint: arc length in metres from its chain's first joint.
  std::vector<double> arc_m;
  uint32_t max_depth() const;
};

// Each chain's branch order: 0 for a root chain, its parent's + 1 otherwise.
std::vector<uint32_t> chain_orders(const Skeleton& skeleton);

// The rig of `skeleton` (validate_skeleton holds). An error (a Diagnostic without place)
// when not even one joint per root chain fits options.max_joints and max_depth.
Expected<Rig> build_rig(const Skeleton& skeleton, const RigOptions& options = {});

// Up to two influences (joint index, weight); count says how many are used.
struct RigWeights {
  std::array<uint32_t, 2> joints{0, 0};
  std::array<float, 2> weights{1, 0};
  int count = 1;
};

// The weights of the point at arc length arc_m along skeleton chain `chain`.
RigWeights rig_weights(const Rig& rig, const Skeleton& skeleton, uint32_t chain, double arc_m);
// The weights of what hangs from `joint` (a leaf's joint, docs/spec/skeleton.md); the
// root's for none.
RigWeights rig_weights_at_joint(const Rig& rig, const Skeleton& skeleton, const std::optional<ChainParent>& joint);

// One joint's world pose: rotation by angle_rad about the sway axis, then at position_m.
struct RigJointPose {
  glm::dvec3 position_m{0};
  double angle_rad = 0;
};

// The pose of every rig joint for the skeleton joints' angles `joint_angles`
// (sway_joint_angles) about the unit `axis`.
std::vector<RigJointPose> pose_rig(const Rig& rig, const glm::dvec3& axis, const std::vector<double>& joint_angles);

// `point_m` (rest, the plant's frame) skinned with `weights` in `pose` (linear blend).
glm::dvec3 skin_point(const Rig& rig, const std::vector<RigJointPose>& pose, const glm::dvec3& axis,
                      const RigWeights& weights, const glm::dvec3& point_m);

// R(θ)·d for the rotation by angle_rad about the unit `axis` (Rodrigues).
glm::dvec3 rotate_about(const glm::dvec3& axis, double angle_rad, const glm::dvec3& d);

}  // namespace sylva
