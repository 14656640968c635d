// growth_tween.cpp — see growth_tween.h.
#include "core/grow/growth_tween.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace sylva {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

// The same point up to rounding: the turtle reaches an old joint through a longer word
// the next step, and its position may differ in the last bits.
bool same_point(const double* a, const double* b) {
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(a[k] - b[k]) <= 1e-9 * (1 + std::abs(a[k])))) return false;
  return true;
}

// The children of each (chain, joint), in chain order.
std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> children_of(const Skeleton& s) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> out;
  for (uint32_t c = 0; c < s.chains.size(); ++c)
    if (s.chains[c].parent) out[{s.chains[c].parent->chain, s.chains[c].parent->joint}].push_back(c);
  return out;
}

double lerp(double a, double b, double t) { return a * (1 - t) + b * t; }

}  // namespace

Skeleton tween_growth(const Skeleton& before, const Skeleton& after, double alpha) {
  Skeleton out = after;
  if (alpha >= 1) return out;  // exactly `after` (a + 1·(b − a) need not be b)
  const size_t chains = after.chains.size();
  // match[c]: the chain of `before` that chain c of `after` continues, or kNone.
  std::vector<uint32_t> match(chains, kNone);
  std::vector<bool> joint_is_new(after.joints.size(), true);
  const auto before_children = children_of(before);
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> taken;  // children of a joint matched so far
  uint32_t before_roots = 0;
  std::vector<uint32_t> roots;
  for (uint32_t c = 0; c < before.chains.size(); ++c)
    if (!before.chains[c].parent) roots.push_back(c);
  for (uint32_t c = 0; c < chains; ++c) {
    const Chain& a = after.chains[c];
    uint32_t candidate = kNone;
    if (!a.parent) {
      if (before_roots < roots.size()) candidate = roots[before_roots++];
    } else {
      const uint32_t parent = match[a.parent->chain];
      const uint32_t parent_first = after.chains[a.parent->chain].first_joint;
      if (parent != kNone && !joint_is_new[parent_first + a.parent->joint]) {
        const std::pair<uint32_t, uint32_t> at{parent, a.parent->joint};
        auto siblings = before_children.find(at);
        uint32_t& next = taken[at];
        if (siblings != before_children.end() && next < siblings->second.size()) {
          const uint32_t b = siblings->second[next];
          const Chain& bc = before.chains[b];
          const bool same_start = a.joint_count < 2 || bc.joint_count < 2 ||
                                  same_point(after.joints[a.first_joint + 1].position_m, before.joints[bc.first_joint + 1].position_m);
          if (same_start) {
            candidate = b;
            ++next;
          }
        }
      }
    }
    match[c] = candidate;
    // Interpolate: common joints lerp, the rest grow out of the last common joint (or,
    // unmatched, out of the attachment joint already interpolated, or the chain's start).
    uint32_t common = 0;
    if (candidate != kNone) common = std::min(a.joint_count, before.chains[candidate].joint_count);
    for (uint32_t j = 0; j < common; ++j) {
      const Joint& jb = before.joints[before.chains[candidate].first_joint + j];
      const Joint& ja = after.joints[a.first_joint + j];
      Joint& jo = out.joints[a.first_joint + j];
      for (int k = 0; k < 3; ++k) jo.position_m[k] = lerp(jb.position_m[k], ja.position_m[k], alpha);
      jo.radius_m = lerp(jb.radius_m, ja.radius_m, alpha);
      joint_is_new[a.first_joint + j] = false;
    }
    // The anchor: where the new part starts, in `after` and in the result.
    const Joint* anchor_after = nullptr;
    const Joint* anchor_out = nullptr;
    uint32_t first_new = common;
    if (common > 0) {
      anchor_after = &after.joints[a.first_joint + common - 1];
      anchor_out = &out.joints[a.first_joint + common - 1];
    } else if (a.parent) {
      const uint32_t at = after.chains[a.parent->chain].first_joint + a.parent->joint;
      anchor_after = &after.joints[at];
      anchor_out = &out.joints[at];
    } else {
      anchor_after = &after.joints[a.first_joint];  // a new root grows out of its own start
      anchor_out = anchor_after;
    }
    for (uint32_t j = first_new; j < a.joint_count; ++j) {
      const Joint& ja = after.joints[a.first_joint + j];
      Joint& jo = out.joints[a.first_joint + j];
      for (int k = 0; k < 3; ++k)
        jo.position_m[k] = anchor_out->position_m[k] + alpha * (ja.position_m[k] - anchor_after->position_m[k]);
      jo.radius_m = alpha * ja.radius_m;
    }
  }
  // The leaves `before` has, by the joint they hang from.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<const Leaf*>> before_leaves;
  for (const Leaf& leaf : before.leaves)
    if (leaf.joint) before_leaves[{leaf.joint->chain, leaf.joint->joint}].push_back(&leaf);
  // Whether `before` has leaf `la` of `after`: on the matched joint, with the same vertices.
  auto had = [&](const Leaf& la) {
    const uint32_t m = match[la.joint->chain];
    const uint32_t at = after.chains[la.joint->chain].first_joint + la.joint->joint;
    if (m == kNone || joint_is_new[at]) return false;
    auto found = before_leaves.find({m, la.joint->joint});
    if (found == before_leaves.end()) return false;
    for (const Leaf* lb : found->second) {
      bool same = lb->vertices_m.size() == la.vertices_m.size();
      for (size_t v = 0; same && v < la.vertices_m.size(); ++v)
        same = same_point(la.vertices_m[v].data(), lb->vertices_m[v].data());
      if (same) return true;
    }
    return false;
  };
  for (size_t i = 0; i < after.leaves.size(); ++i) {
    const Leaf& la = after.leaves[i];
    if (!la.joint) continue;
    const uint32_t at = after.chains[la.joint->chain].first_joint + la.joint->joint;
    const double scale = had(la) ? 1.0 : alpha;
    const Joint& ja = after.joints[at];
    const Joint& jo = out.joints[at];
    for (size_t v = 0; v < la.vertices_m.size(); ++v)
      for (int k = 0; k < 3; ++k)
        out.leaves[i].vertices_m[v][k] = jo.position_m[k] + scale * (la.vertices_m[v][k] - ja.position_m[k]);
  }
  return out;
}

}  // namespace sylva
