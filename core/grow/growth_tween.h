// growth_tween.h — a plant between two derivation steps (issue 31 §3): the frames of
// `render --frames all --substeps K` between step n and n + 1, so that branches grow
// out instead of appearing at full length.
//
// The skeleton `after` (step n + 1) is matched to `before` (step n) chain by chain,
// parents first: the k-th root chain to the k-th root chain; a lateral to the lateral of
// the matched parent that leaves the same joint in the same order, when that joint
// existed before and the two chains' second joints coincide. A matched chain's joints
// that both skeletons have are interpolated linearly (position and radius); its joints
// past `before`'s end grow out of the interpolated last common joint, their offsets from
// it scaled by alpha, their radii by alpha. An unmatched chain grows the same way out of
// its interpolated attachment joint (a root chain out of its own first joint). A leaf
// `before` had (on the matched joint, with the same vertices) moves with its joint; any
// other leaf grows by alpha about its joint. Positions count as the same up to 1e-9
// relative: the turtle reaches an old joint through a longer word the next step. The result has `after`'s chains, joints and leaves in
// `after`'s order: alpha = 1 gives `after` exactly, alpha → 0 shrinks what is new to
// points. What this assumes: growth adds to the ends of axes and new laterals (what
// L-systems with apices do); a step that rewrites old geometry is interpolated joint by
// joint where the counts allow, and otherwise grows out as new.
#pragma once

#include "core/geometry/skeleton.h"

namespace sylva {

// Precondition: 0 < alpha <= 1; both skeletons valid (validate_skeleton). The result is
// valid and carries `after`'s source.
Skeleton tween_growth(const Skeleton& before, const Skeleton& after, double alpha);

}  // namespace sylva
