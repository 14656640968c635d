// crotch.cpp — see crotch.h.
#include "core/geometry/crotch.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>

namespace sylva {

namespace {

using glm::dvec3;

dvec3 joint_position(const Joint& j) { return {j.position_m[0], j.position_m[1], j.position_m[2]}; }

// A ball holding the frustum's solid: its cuts are tilted at most 80° (skin.h G1), so the
// solid reaches past each end of its axis by at most r·tan(tilt); 1.8·r holds the 60° the
// skinning uses, and the test below adds the ball's own radius, so a looser bound only
// costs a frustum more in a group.
struct Sphere {
  dvec3 centre;
  double radius;
};
Sphere bounding_sphere(const FrustumShape& s) {
  const double r = std::max(s.radius0, s.radius1);
  const double half = 0.5 * s.length + 1.8 * r;
  return {s.base + 0.5 * s.length * s.axis, std::sqrt(half * half + r * r)};
}

bool touches(const FrustumShape& s, const dvec3& centre, double radius) {
  const Sphere b = bounding_sphere(s);
  return glm::length(b.centre - centre) <= b.radius + radius;
}

double group_bound(std::span<const Frustum> frusta, const std::vector<uint32_t>& group, const dvec3& p) {
  double d = std::numeric_limits<double>::infinity();
  for (uint32_t i : group) d = std::min(d, frustum_bound(frusta[i].shape, p));
  return d;
}

double depth_at(const Crotch& c, double s) {
  if (c.depth.empty()) return 0;
  const double x = s / c.depth_step - 0.5;
  if (!(x > 0)) return c.depth.front();
  const size_t i = static_cast<size_t>(x);
  if (i + 1 >= c.depth.size()) return c.depth.back();
  const double f = x - static_cast<double>(i);
  return c.depth[i] + f * (c.depth[i + 1] - c.depth[i]);
}

}  // namespace

double frustum_bound(const FrustumShape& shape, const dvec3& p) {
  const dvec3 w = p - shape.base;
  const double y = glm::dot(w, shape.axis);
  const double rho = glm::length(w - y * shape.axis);
  const double slope = shape.slope();
  const double cone = (rho - shape.radius_at(y)) / std::sqrt(1 + slope * slope);
  const double lower = shape.lower.offset - glm::dot(shape.lower.normal, p);
  const double upper = glm::dot(shape.upper.normal, p) - shape.upper.offset;
  return std::max(cone, std::max(lower, upper));
}

std::vector<Crotch> find_crotches(const Skeleton& sk, std::span<const Frustum> frusta, const CrotchOptions& options) {
  std::vector<Crotch> out;
  const size_t chains = sk.chains.size();
  // Each chain's frusta are one run of the array (skin.h).
  std::vector<uint32_t> first(chains, 0), count(chains, 0);
  for (uint32_t i = 0; i < frusta.size(); ++i) {
    const uint32_t c = frusta[i].chain;
    if (count[c]++ == 0) first[c] = i;
  }
  const std::vector<int64_t> continuation = continuation_children(sk);
  for (uint32_t c = 0; c < chains; ++c) {
    const Chain& ch = sk.chains[c];
    if (!ch.parent || count[c] == 0) continue;
    const uint32_t pc = ch.parent->chain;
    if (continuation[pc] == int64_t(c)) continue;
    const Chain& parent = sk.chains[pc];
    const double big_r = sk.joints[parent.first_joint + ch.parent->joint].radius_m;
    const double r_l = sk.joints[ch.first_joint].radius_m;
    if (!(big_r > 0) || !(r_l >= options.min_ratio * big_r)) continue;
    const std::optional<dvec3> parent_dir = chain_direction_at(sk, parent, ch.parent->joint);
    const dvec3 start = joint_position(sk.joints[ch.first_joint]);
    std::optional<dvec3> dir;
    double first_length = 0;
    for (uint32_t j = 1; j < ch.joint_count && !dir; ++j) {
      const dvec3 d = joint_position(sk.joints[ch.first_joint + j]) - start;
      if (glm::length(d) > 0) dir = glm::normalize(d), first_length = glm::length(d);
    }
    if (!dir || !parent_dir) continue;
    const bool at_end = ch.parent->joint + 1 == parent.joint_count;
    const double sin_t = glm::length(glm::cross(*dir, *parent_dir));
    const double t_exit = at_end ? big_r : big_r / std::max(sin_t, 1e-6);
    if (!(t_exit < first_length)) continue;  // its first segment stays inside the parent

    Crotch cr;
    cr.lateral = c;
    cr.start = start;
    cr.direction = *dir;
    cr.centre = start + t_exit * *dir;
    cr.k = options.blend * r_l;
    cr.lateral_radius = r_l;
    // The crease lies within r / sin θ of the centre (for a parent much wider than the
    // lateral): the ball holds it with room for the fade, which is still 0.84 there.
    cr.radius = 1.5 * r_l / std::max(sin_t, 0.5) + cr.k;
    // The parent's group: the parent chain, its continuation, the lateral's siblings.
    std::vector<uint32_t> group_chains{pc};
    if (continuation[pc] >= 0 && continuation[pc] != int64_t(c)) group_chains.push_back(uint32_t(continuation[pc]));
    for (uint32_t o = pc + 1; o < chains; ++o) {
      const Chain& other = sk.chains[o];
      if (o != c && other.parent && *other.parent == *ch.parent && int64_t(o) != continuation[pc]) group_chains.push_back(o);
    }
    for (uint32_t g : group_chains) {
      for (uint32_t i = first[g]; i < first[g] + count[g]; ++i) {
        if (touches(frusta[i].shape, cr.centre, cr.radius)) cr.parent_frusta.push_back(i);
      }
    }
    for (uint32_t i = first[c]; i < first[c] + count[c]; ++i) {
      if (touches(frusta[i].shape, cr.centre, cr.radius)) cr.lateral_frusta.push_back(i);
    }
    if (cr.parent_frusta.empty() || cr.lateral_frusta.empty()) continue;
    cr.depth_step = (t_exit + cr.radius) / static_cast<int>(kCrotchDepthSamples);
    for (int i = 0; i < static_cast<int>(kCrotchDepthSamples); ++i) {
      const dvec3 q = start + (i + 0.5) * cr.depth_step * *dir;
      cr.depth.push_back(-group_bound(frusta, cr.parent_frusta, q));
    }
    out.push_back(std::move(cr));
  }
  return out;
}

bool crotch_seen(const Crotch& c, const dvec3& eye, double pixels_per_radian, double min_pixels) {
  const double distance = glm::length(c.centre - eye) - c.radius;
  return !(distance > 0) || c.k * pixels_per_radian >= min_pixels * distance;
}

bool crotch_seen_from_any(const Crotch& c, std::span<const dvec3> eyes, double pixels_per_radian, double min_pixels) {
  return std::any_of(eyes.begin(), eyes.end(),
                     [&](const dvec3& eye) { return crotch_seen(c, eye, pixels_per_radian, min_pixels); });
}

std::vector<Crotch> crotches_seen(std::vector<Crotch> crotches, std::span<const dvec3> eyes,
                                  double pixels_per_radian) {
  std::erase_if(crotches, [&](const Crotch& c) { return !crotch_seen_from_any(c, eyes, pixels_per_radian); });
  return crotches;
}

CrotchSample crotch_field(const Crotch& c, std::span<const Frustum> frusta, const dvec3& p) {
  CrotchSample s;
  s.parent = group_bound(frusta, c.parent_frusta, p);
  s.lateral = group_bound(frusta, c.lateral_frusta, p);
  const double x2 = glm::dot(p - c.centre, p - c.centre) / (c.radius * c.radius);
  if (x2 < 1 && c.k > 0) {
    const double ball = (1 - x2 * x2) * (1 - x2 * x2);  // flat inside, C1 to 0 at the rim
    // Wholly under the parent's surface where the axis is deeper than the section's radius.
    const double d = depth_at(c, glm::dot(p - c.start, c.direction));
    const double u = std::clamp((d - c.lateral_radius) / c.k, 0.0, 1.0);
    const double depth = 1 - u * u * (3 - 2 * u);
    s.k = c.k * ball * depth;
  }
  const double lo = std::min(s.parent, s.lateral);
  if (s.k > 0) {
    const double gap = std::abs(s.parent - s.lateral);
    const double h = std::max(s.k - gap, 0.0) / s.k;
    s.value = lo - h * h * s.k / 4;
    s.h = std::clamp(0.5 + 0.5 * (s.lateral - s.parent) / s.k, 0.0, 1.0);
  } else {
    s.value = lo;
    s.h = s.parent < s.lateral ? 1.0 : (s.parent > s.lateral ? 0.0 : 0.5);
  }
  return s;
}

namespace {

// The frustum of `group` that shades p: the least bound among those whose slab holds p,
// else the least bound.
uint32_t shading_frustum(std::span<const Frustum> frusta, const std::vector<uint32_t>& group, const dvec3& p) {
  uint32_t best = group.front(), best_in_slab = 0;
  double least = std::numeric_limits<double>::infinity(), least_in_slab = least;
  for (uint32_t i : group) {
    const FrustumShape& f = frusta[i].shape;
    const double b = frustum_bound(f, p);
    if (b < least) least = b, best = i;
    const bool in_slab = glm::dot(f.lower.normal, p) >= f.lower.offset && glm::dot(f.upper.normal, p) <= f.upper.offset;
    if (in_slab && b < least_in_slab) least_in_slab = b, best_in_slab = i;
  }
  return least_in_slab < std::numeric_limits<double>::infinity() ? best_in_slab : best;
}

}  // namespace

CrotchShade crotch_shade(const Crotch& c, std::span<const Frustum> frusta, const dvec3& p) {
  CrotchShade s;
  s.h = crotch_field(c, frusta, p).h;
  s.parent_frustum = shading_frustum(frusta, c.parent_frusta, p);
  s.lateral_frustum = shading_frustum(frusta, c.lateral_frusta, p);
  const Frustum& fp = frusta[s.parent_frustum];
  const Frustum& fl = frusta[s.lateral_frustum];
  const dvec3 np = surface_normal(fp, p, NormalMode::interpolated);
  const dvec3 nl = surface_normal(fl, p, NormalMode::interpolated);
  const dvec3 n = s.h * np + (1 - s.h) * nl;
  // Opposite normals (a point between two facing surfaces) mix to ~0: keep the heavier.
  s.normal = glm::length(n) > 1e-6 ? glm::normalize(n) : (s.h >= 0.5 ? np : nl);
  s.parent_uv = surface_uv(fp, p);
  s.lateral_uv = surface_uv(fl, p);
  return s;
}

double crotch_relief_fade(const CrotchSample& s) {
  if (!(s.k > 0)) return 1;
  const double x = std::clamp((std::abs(s.parent - s.lateral) - s.k) / s.k, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

CrotchesOfFrusta crotches_of_frusta(std::span<const Crotch> crotches, size_t frustum_count) {
  CrotchesOfFrusta out;
  out.begin.assign(frustum_count + 1, 0);
  for (const Crotch& c : crotches) {
    for (uint32_t f : c.parent_frusta) ++out.begin[f + 1];
    for (uint32_t f : c.lateral_frusta) ++out.begin[f + 1];
  }
  for (size_t i = 1; i < out.begin.size(); ++i) out.begin[i] += out.begin[i - 1];
  out.crotches.resize(out.begin.back());
  std::vector<uint32_t> next(out.begin.begin(), out.begin.end() - 1);
  for (uint32_t c = 0; c < crotches.size(); ++c) {
    for (uint32_t f : crotches[c].parent_frusta) out.crotches[next[f]++] = c;
    for (uint32_t f : crotches[c].lateral_frusta) out.crotches[next[f]++] = c;
  }
  return out;
}

double relief_fade_at(std::span<const Crotch> crotches, std::span<const uint32_t> which,
                      std::span<const Frustum> frusta, const dvec3& p) {
  double fade = 1;
  for (uint32_t i : which) {
    const Crotch& c = crotches[i];
    if (glm::dot(p - c.centre, p - c.centre) >= c.radius * c.radius) continue;  // k = 0 there
    fade = std::min(fade, crotch_relief_fade(crotch_field(c, frusta, p)));
  }
  return fade;
}

std::optional<CrotchHit> march_crotch(const Crotch& c, std::span<const Frustum> frusta, const Ray& ray,
                                      double t_min, double t_max, bool fillet_only) {
  // The ball, as a stable quadratic in t re-centred at the ball's centre.
  const dvec3 o = ray.origin - c.centre;
  const double a = glm::dot(ray.direction, ray.direction);
  const double half_b = glm::dot(o, ray.direction);
  // (|o|² − R²)·a − half_b² without cancelling: |o × d|² − R²·a.
  const dvec3 m = glm::cross(o, ray.direction);
  const double disc = c.radius * c.radius * a - glm::dot(m, m);
  if (!(disc > 0) || !(a > 0)) return std::nullopt;
  const double root = std::sqrt(disc);
  const double q = -(half_b + (half_b >= 0 ? root : -root));
  double t0 = q / a, t1 = q != 0 ? (glm::dot(o, o) - c.radius * c.radius) / q : -t0;
  if (t1 < t0) std::swap(t0, t1);
  double lo = std::max(t0, t_min), hi = std::min(t1, t_max);
  if (!(lo < hi)) return std::nullopt;

  const double speed = std::sqrt(a);
  const double min_step = 2.5e-4 * c.radius / speed;
  const double eps = 1e-7 * c.radius;
  auto sample = [&](double t) { return crotch_field(c, frusta, ray.origin + t * ray.direction); };
  auto field = [&](double t) { return sample(t).value; };
  // How far the solid {F <= 0} is at least: its exact part (min(P, C) <= 0) is at least
  // min(P, C) away, and its fillet (F <= 0 < min(P, C)) needs |P − C| < k and
  // min(P, C) <= k/4, so max(P, C) < 5k/4, at least max(P, C) − 5k/4 away (P and C are
  // 1-Lipschitz). That is often far more than F / kCrotchLipschitz: beside one group's
  // surface, away from the other's, and where the march closes in on the exact surface.
  auto clearance = [&](const CrotchSample& s) {
    return std::max(s.value / kCrotchLipschitz,
                    std::min(std::min(s.parent, s.lateral), std::max(s.parent, s.lateral) - 1.25 * c.k));
  };
  CrotchHit hit;
  double t = lo;
  CrotchSample s = sample(t);
  hit.steps = 1;
  if (!(s.value > 0)) return std::nullopt;  // inside at entry: the exact surface is in front
  constexpr int kMaxSteps = 4096;
  while (hit.steps < kMaxSteps) {
    if (fillet_only && std::abs(s.parent - s.lateral) - 2 * (hi - t) * speed >= c.k) return std::nullopt;
    const double step = std::max(clearance(s) / speed, min_step);
    const double t_next = t + step;
    if (t_next >= hi) return std::nullopt;
    const CrotchSample s_next = sample(t_next);
    const double f_next = s_next.value;
    ++hit.steps;
    if (f_next <= eps) {
      if (f_next >= 0) {
        hit.t = t_next;
        return hit;
      }
      // A minimum step landed inside: bisect back to the crossing.
      double a_t = t, b_t = t_next;
      while ((b_t - a_t) * speed > eps && hit.steps < kMaxSteps) {
        const double mid = 0.5 * (a_t + b_t);
        (field(mid) > 0 ? a_t : b_t) = mid;
        ++hit.steps;
      }
      hit.t = b_t;
      return hit;
    }
    t = t_next;
    s = s_next;
  }
  return std::nullopt;
}

}  // namespace sylva
