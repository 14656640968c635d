// gltf_rig.cpp — see gltf_rig.h.
#include "core/io/gltf_rig.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <glm/geometric.hpp>

namespace sylva {

namespace {

glm::dvec3 position_of(const Joint& j) { return {j.position_m[0], j.position_m[1], j.position_m[2]}; }

// Joints a rigged chain of n joints gets with a joint every k internodes: local 0, k, 2k,
// … below the tip.
uint32_t chain_rig_joints(uint32_t n, uint32_t k) { return (n - 2) / k + 1; }

// The chains of a candidate rig and what they cost with a joint every k internodes.
class RigPlan {
 public:
  RigPlan(const Skeleton& sk, uint32_t k) : sk_(sk), k_(k), in_(sk.chains.size(), false), base_depth_(sk.chains.size(), 0) {}

  // Adds chain c (its parent chain already decided) if it still fits; says whether it did.
  bool add(uint32_t c, const RigOptions& options) {
    const uint32_t count = chain_rig_joints(sk_.chains[c].joint_count, k_);
    const uint32_t base = attach_depth(c) + 1;
    const uint64_t deepest = uint64_t{base} + count - 1;
    if (joints_ + count > options.max_joints || deepest > options.max_depth) return false;
    in_[c] = true;
    base_depth_[c] = base;
    joints_ += count;
    return true;
  }

  bool has(uint32_t c) const { return in_[c]; }
  uint32_t joints() const { return joints_; }

 private:
  // Depth of the rig joint chain c's first joint hangs from (0: the root).
  uint32_t attach_depth(uint32_t c) const {
    std::optional<ChainParent> at = sk_.chains[c].parent;
    while (at) {
      if (in_[at->chain]) {
        const uint32_t count = chain_rig_joints(sk_.chains[at->chain].joint_count, k_);
        return base_depth_[at->chain] + std::min(at->joint / k_, count - 1);
      }
      at = sk_.chains[at->chain].parent;
    }
    return 0;
  }

  const Skeleton& sk_;
  uint32_t k_;
  std::vector<bool> in_;
  std::vector<uint32_t> base_depth_;
  uint32_t joints_ = 1;  // the root
};

// The plan rigging every riggable chain of order ≤ order with step k, if it fits.
std::optional<RigPlan> full_plan(const Skeleton& sk, const std::vector<uint32_t>& order_of, uint32_t order, uint32_t k,
                                 const RigOptions& options) {
  RigPlan plan(sk, k);
  for (uint32_t c = 0; c < sk.chains.size(); ++c)
    if (sk.chains[c].joint_count >= 2 && order_of[c] <= order && !plan.add(c, options)) return std::nullopt;
  return plan;
}

}  // namespace

std::vector<uint32_t> chain_orders(const Skeleton& sk) {
  std::vector<uint32_t> order(sk.chains.size(), 0);
  for (size_t c = 0; c < sk.chains.size(); ++c)
    if (sk.chains[c].parent) order[c] = order[sk.chains[c].parent->chain] + 1;
  return order;
}

uint32_t Rig::max_depth() const {
  uint32_t d = 0;
  for (const RigJoint& j : joints) d = std::max(d, j.depth);
  return d;
}

Expected<Rig> build_rig(const Skeleton& sk, const RigOptions& options) {
  const uint32_t chains = static_cast<uint32_t>(sk.chains.size());
  const std::vector<uint32_t> order_of = chain_orders(sk);
  std::vector<double> own_length(chains, 0), subtree_length(chains, 0);
  Rig rig;
  rig.arc_m.assign(sk.joints.size(), 0.0);
  uint32_t longest = 1;  // the most internodes of one chain
  for (uint32_t c = 0; c < chains; ++c) {
    const Chain& chain = sk.chains[c];
    for (uint32_t i = chain.first_joint + 1; i < chain.first_joint + chain.joint_count; ++i)
      rig.arc_m[i] = rig.arc_m[i - 1] + glm::length(position_of(sk.joints[i]) - position_of(sk.joints[i - 1]));
    own_length[c] = rig.arc_m[chain.first_joint + chain.joint_count - 1];
    longest = std::max(longest, chain.joint_count - 1);
  }
  for (uint32_t c = chains; c-- > 0;) {
    subtree_length[c] += own_length[c];
    if (sk.chains[c].parent) subtree_length[sk.chains[c].parent->chain] += subtree_length[c];
  }

  // The largest order whose chains all fit with some step, and the smallest such step
  // (what fits with k fits with every larger k: fewer joints, no deeper).
  std::optional<RigPlan> plan;
  uint32_t order = options.max_order + 1;
  while (!plan && order-- > 0) {
    if (!full_plan(sk, order_of, order, longest, options)) continue;
    uint32_t lo = 1, hi = longest;
    while (lo < hi) {
      const uint32_t mid = lo + (hi - lo) / 2;
      if (full_plan(sk, order_of, order, mid, options)) hi = mid;
      else lo = mid + 1;
    }
    rig.step = lo;
    plan.emplace(*full_plan(sk, order_of, order, lo, options));
  }
  if (!plan) {
    uint32_t roots = 0;
    for (const Chain& c : sk.chains) roots += !c.parent && c.joint_count >= 2;
    return file_diagnostic("", "the plant has " + std::to_string(roots) + " root chains: a rig of at most " +
                              std::to_string(options.max_joints) + " joints (the root counted) cannot give each one");
  }
  rig.full_order = order;
  // Then the next order's chains, longest subtrees first, while they fit.
  if (order < options.max_order) {
    std::vector<uint32_t> next;
    for (uint32_t c = 0; c < chains; ++c)
      if (sk.chains[c].joint_count >= 2 && order_of[c] == order + 1) next.push_back(c);
    std::stable_sort(next.begin(), next.end(),
                     [&](uint32_t a, uint32_t b) { return subtree_length[a] > subtree_length[b]; });
    for (uint32_t c : next) plan->add(c, options);
  }

  // The joints, chain by chain (parents first).
  rig.joints.push_back(RigJoint{});
  rig.chain_joints.assign(chains, {});
  for (uint32_t c = 0; c < chains; ++c) {
    if (!plan->has(c)) continue;
    ++rig.rigged_chains;
    const Chain& chain = sk.chains[c];
    uint32_t parent = 0;
    for (std::optional<ChainParent> at = chain.parent; at;) {
      const std::vector<uint32_t>& up = rig.chain_joints[at->chain];
      if (!up.empty()) {
        parent = up[std::min<size_t>(at->joint / rig.step, up.size() - 1)];
        break;
      }
      at = sk.chains[at->chain].parent;  // an unrigged chain hangs where it grows from
    }
    for (uint32_t local = 0; local + 1 < chain.joint_count; local += rig.step) {
      RigJoint j;
      j.skeleton_joint = chain.first_joint + local;
      j.chain = c;
      j.parent = parent;
      j.position_m = position_of(sk.joints[j.skeleton_joint]);
      j.depth = rig.joints[parent].depth + 1;
      parent = static_cast<uint32_t>(rig.joints.size());
      rig.joints.push_back(j);
      rig.chain_joints[c].push_back(parent);
    }
  }
  return rig;
}

RigWeights rig_weights(const Rig& rig, const Skeleton& sk, uint32_t chain, double arc_m) {
  // Up to the nearest rigged chain, at the point this one grows from.
  while (rig.chain_joints[chain].empty()) {
    const std::optional<ChainParent>& parent = sk.chains[chain].parent;
    if (!parent) return RigWeights{};  // the root
    chain = parent->chain;
    arc_m = rig.arc_m[sk.chains[chain].first_joint + parent->joint];
  }
  const std::vector<uint32_t>& along = rig.chain_joints[chain];
  auto arc_of = [&](uint32_t j) { return rig.arc_m[rig.joints[j].skeleton_joint]; };
  // The first rig joint past arc_m; the one before it brackets arc_m from below.
  const auto upper = std::upper_bound(along.begin(), along.end(), arc_m,
                                      [&](double s, uint32_t j) { return s < arc_of(j); });
  if (upper == along.begin()) return RigWeights{{along.front(), 0}, {1, 0}, 1};
  const uint32_t a = *(upper - 1);
  if (upper == along.end()) return RigWeights{{a, 0}, {1, 0}, 1};
  const uint32_t b = *upper;
  const double t = (arc_m - arc_of(a)) / (arc_of(b) - arc_of(a));
  const float wb = static_cast<float>(std::clamp(t, 0.0, 1.0));
  if (wb <= 0) return RigWeights{{a, 0}, {1, 0}, 1};
  if (wb >= 1) return RigWeights{{b, 0}, {1, 0}, 1};
  return RigWeights{{a, b}, {1.0f - wb, wb}, 2};
}

RigWeights rig_weights_at_joint(const Rig& rig, const Skeleton& sk, const std::optional<ChainParent>& joint) {
  if (!joint) return RigWeights{};
  return rig_weights(rig, sk, joint->chain, rig.arc_m[sk.chains[joint->chain].first_joint + joint->joint]);
}

glm::dvec3 rotate_about(const glm::dvec3& axis, double angle_rad, const glm::dvec3& d) {
  const glm::dvec3 across = glm::cross(axis, d);
  const double half_sin = std::sin(0.5 * angle_rad);
  return d + std::sin(angle_rad) * across + (2 * half_sin * half_sin) * glm::cross(axis, across);
}

std::vector<RigJointPose> pose_rig(const Rig& rig, const glm::dvec3& axis, const std::vector<double>& joint_angles) {
  std::vector<RigJointPose> pose(rig.joints.size());
  for (size_t j = 1; j < rig.joints.size(); ++j) {
    const RigJoint& joint = rig.joints[j];
    const RigJointPose& parent = pose[joint.parent];
    pose[j].angle_rad = joint_angles[joint.skeleton_joint];
    pose[j].position_m = parent.position_m + rotate_about(axis, parent.angle_rad,
                                                          joint.position_m - rig.joints[joint.parent].position_m);
  }
  return pose;
}

glm::dvec3 skin_point(const Rig& rig, const std::vector<RigJointPose>& pose, const glm::dvec3& axis,
                      const RigWeights& weights, const glm::dvec3& point_m) {
  glm::dvec3 out(0);
  for (int i = 0; i < weights.count; ++i) {
    const uint32_t j = weights.joints[static_cast<size_t>(i)];
    out += static_cast<double>(weights.weights[static_cast<size_t>(i)]) *
           (pose[j].position_m + rotate_about(axis, pose[j].angle_rad, point_m - rig.joints[j].position_m));
  }
  return out;
}

}  // namespace sylva
