// fog_integrator.cpp — the modes of docs/spec/fog.md over the closed forms of fog.h (the header
// and docs/fog.md say what each mode does and why).
#include "core/scene/fog_integrator.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>
#include <stdexcept>

#include "core/util/math.h"

namespace sylva {

using render_common::SampleRng;

// Where shadow rays stop being castable: Embree's rays are float (3.4e38), and a point this
// far is beyond every plant.
constexpr double kFogFloatRange = 1e30;

FogSun fog_sun_of(const Sun& sun) {
  FogSun s;
  s.direction = glm::normalize(sun.direction);
  s.angular_radius_rad = sun.angular_radius_deg * kRadPerDeg;
  s.radiance = sun.radiance;
  return s;
}

FogMedium fog_medium_of(const Scene& scene) {
  const Fog& f = *scene.fog;
  return fog_medium(f.sigma_s, f.sigma_a, f.g, f.height_falloff, scene.ground.height, f.top);
}

FogIntegrator::FogIntegrator(const FogMedium& medium, const FogSun& sun, const glm::dvec3& sky,
                             const SceneTracer& tracer, const FogConeSource* cones,
                             const FogIntegratorOptions& options)
    : medium_(medium), sun_(sun), sky_(sky), tracer_(tracer), cones_(cones),
      mode_(options.mode == FogMode::automatic ? FogMode::refined : options.mode),
      steps_(std::max(1u, options.steps)), maps_(options.maps), map_per_ray_(options.map_per_ray) {
  if (mode_ == FogMode::fast && !cones_)
    throw std::invalid_argument("fog mode fast needs shadow cones (V = 0 inside them): none were given");
  if (mode_ == FogMode::map && maps_.empty())
    throw std::invalid_argument("fog mode map needs sun maps: none were given");
  cos_alpha_ = std::cos(sun_.angular_radius_rad);
  sun_frame_ = axis_frame(sun_.direction);
  const bool radiant = sun_.radiance.x > 0 || sun_.radiance.y > 0 || sun_.radiance.z > 0;
  sunlit_ = radiant && sun_.direction.y > 0 && medium_.albedo > 0 && medium_.sigma_t > 0;
  casters_ = tracer_.bounds();
  // The lowest direction of the disc rises at elevation asin(s_y) − α.
  disc_climbs_ = std::asin(std::clamp(sun_.direction.y, -1.0, 1.0)) > sun_.angular_radius_rad;
}

namespace {

// The intervals of `in` clipped to [a, b], dropping empty ones (in sorted and disjoint).
std::vector<FogInterval> clipped(const std::vector<FogInterval>& in, double a, double b) {
  std::vector<FogInterval> out;
  for (const FogInterval& i : in) {
    const double t0 = std::max(i.t0, a), t1 = std::min(i.t1, b);
    if (t1 > t0) out.push_back({t0, t1});
  }
  return out;
}

// Integrates the sunlit in-scatter over [a, b] where `lit` (sorted, disjoint, inside
// [a, b]) says V = 1, V = 0 elsewhere: closed forms over each piece, the optical depth from
// a carried along.
double integrate_lit(const FogMedium& m, const glm::dvec3& origin, const glm::dvec3& direction,
                     const glm::dvec3& sun, double a, const std::vector<FogInterval>& lit) {
  double depth = 0, t = a, total = 0;
  for (const FogInterval& piece : lit) {
    if (piece.t0 > t) depth += fog_optical_depth(m, origin, direction, t, piece.t0);
    const FogSegment s = fog_lit_segment(m, origin, direction, sun, piece.t0, piece.t1, depth);
    total += s.sun;
    depth += s.depth;
    t = piece.t1;
    if (depth > kFogMaxDepth) break;  // nothing further can add
  }
  return total;
}

// Whether the ray origin + u·direction, u >= 0, meets `box` (slabs; an empty box never).
bool meets_box(const glm::dvec3& origin, const glm::dvec3& direction, const Aabb& box) {
  double u0 = 0, u1 = kFogInfinity;
  for (int i = 0; i < 3; ++i) {
    if (!(box.lo[i] <= box.hi[i])) return false;
    if (direction[i] == 0) {
      if (origin[i] < box.lo[i] || origin[i] > box.hi[i]) return false;
      continue;
    }
    double near = (box.lo[i] - origin[i]) / direction[i], far = (box.hi[i] - origin[i]) / direction[i];
    if (near > far) std::swap(near, far);
    u0 = std::max(u0, near), u1 = std::min(u1, far);
    if (!(u0 <= u1)) return false;
  }
  return true;
}

}  // namespace

glm::dvec3 FogIntegrator::disc_direction(SampleRng& rng) const {
  if (sun_.angular_radius_rad <= 0) return sun_.direction;
  return render_common::sample_sun_disc(sun_.direction, cos_alpha_, sun_frame_, rng);
}

double FogIntegrator::visible(const CameraRay& ray, double t, const glm::dvec3& toward_sun, FogRayResult* result) const {
  // Only plants shadow the fog (the ground never lies between a point above it and a sun
  // above the horizon), and only where the sun ray meets their box: elsewhere (a point of
  // an unbounded ray far beyond the plants included, docs/fog.md) no shadow ray is cast.
  // Beyond float's range (an unbounded ray's far probes) Embree's rays are invalid; such a
  // point is far outside every plant anyway.
  const glm::dvec3 point = ray.origin + t * ray.direction;
  if (!(std::max({std::abs(point.x), std::abs(point.y), std::abs(point.z)}) < kFogFloatRange)) return 1.0;
  if (!meets_box(point, toward_sun, casters_)) return 1.0;
  ++result->shadow_rays;
  return tracer_.any(Ray{point, toward_sun}, 0, kFogInfinity) ? 0.0 : 1.0;
}

FogInterval FogIntegrator::shadow_range(const CameraRay& ray, double a, double b) const {
  if (!(casters_.lo.y <= casters_.hi.y)) return {a, a};  // nothing casts a shadow
  if (!disc_climbs_) return {a, b};
  const double dy = ray.direction.y, above = ray.origin.y - casters_.hi.y;  // y(t) − top = above + t·dy
  if (dy > 0) return {a, std::clamp(-above / dy, a, b)};
  if (dy < 0) return {std::clamp(-above / dy, a, b), b};
  return above > 0 ? FogInterval{a, a} : FogInterval{a, b};
}

double FogIntegrator::sun_brute(const CameraRay& ray, double a, double b, const std::vector<FogInterval>* cones,
                                SampleRng& rng, FogRayResult* result) const {
  const glm::dvec3& s = sun_.direction;
  const double weight = fog_lit_segment(medium_, ray.origin, ray.direction, s, a, b, 0).sun;
  if (!(weight > 0)) return 0;
  double visible_sum = 0;
  size_t cone = 0;
  for (uint32_t k = 0; k < steps_; ++k) {
    // Sample k at the share (k + ξ)/steps of the unshadowed weight: increasing in k.
    const double xi = (k + rng.next_double()) / steps_;
    const double t = fog_sample_lit_segment(medium_, ray.origin, ray.direction, s, a, b, xi);
    if (cones) {  // medium: outside every cone the sun is taken as visible
      while (cone < cones->size() && (*cones)[cone].t1 < t) ++cone;
      if (cone == cones->size() || (*cones)[cone].t0 > t) {
        visible_sum += 1;
        continue;
      }
    }
    visible_sum += visible(ray, t, disc_direction(rng), result);
  }
  return weight * visible_sum / steps_;
}

double FogIntegrator::sun_fast(const CameraRay& ray, double a, double b, const std::vector<FogInterval>& cones) const {
  std::vector<FogInterval> lit;
  double t = a;
  for (const FogInterval& c : cones) {
    append_lit(&lit, t, c.t0);
    t = std::max(t, c.t1);
  }
  append_lit(&lit, t, b);
  return integrate_lit(medium_, ray.origin, ray.direction, sun_.direction, a, lit);
}

double FogIntegrator::sun_map(const CameraRay& ray, double a, double b, const std::vector<FogInterval>& cones,
                              SampleRng& rng, FogRayResult* result) const {
  thread_local std::vector<FogInterval> lit;
  SunMapWalkStats stats;
  double sum = 0;
  std::span<const SunDepthMap> maps = maps_;
  if (map_per_ray_ && maps.size() > 1) {
    const size_t k = std::min(maps.size() - 1, static_cast<size_t>(rng.next_double() * maps.size()));
    maps = maps.subspan(k, 1);
  }
  for (const SunDepthMap& map : maps) {
    lit.clear();
    double t = a;
    for (const FogInterval& c : cones) {
      append_lit(&lit, t, c.t0);  // outside the cones the sun is visible
      map.lit_parts(ray.origin, ray.direction, c.t0, c.t1, &lit, &stats);
      t = c.t1;
    }
    append_lit(&lit, t, b);
    sum += integrate_lit(medium_, ray.origin, ray.direction, sun_.direction, a, lit);
  }
  result->map_texels += stats.texels;
  return sum / maps.size();
}

double FogIntegrator::sun_refined(const CameraRay& ray, double a, double b, const std::vector<FogInterval>& search,
                                  uint32_t probes, int bisections, const glm::dvec3& toward_sun, SampleRng& rng,
                                  FogRayResult* result) const {
  const glm::dvec3& s = sun_.direction;
  // Each searched interval's unshadowed weight, to share the probes by.
  std::vector<double> weights(search.size(), 0.0);
  double total_weight = 0;
  {
    double depth = 0, t = a;
    for (size_t j = 0; j < search.size(); ++j) {
      depth += fog_optical_depth(medium_, ray.origin, ray.direction, t, search[j].t0);
      const FogSegment seg = fog_lit_segment(medium_, ray.origin, ray.direction, s, search[j].t0, search[j].t1, depth);
      weights[j] = seg.sun;
      total_weight += seg.sun;
      depth += seg.depth;
      t = search[j].t1;
    }
  }
  std::vector<FogInterval> lit;
  std::vector<double> at;      // probe positions within one interval
  std::vector<double> shown;   // V there
  double t = a;
  for (size_t j = 0; j < search.size(); ++j) {
    const FogInterval& in = search[j];
    append_lit(&lit, t, in.t0);  // outside the searched intervals the sun is visible
    t = in.t1;
    // An interval of negligible weight is not probed: whatever its shadow, it cannot matter.
    if (!(weights[j] > 1e-12 * total_weight)) {
      append_lit(&lit, in.t0, in.t1);
      continue;
    }
    const uint32_t n = static_cast<uint32_t>(std::llround(probes * weights[j] / total_weight));
    at.assign(1, in.t0);
    for (uint32_t i = 0; i < n; ++i) {
      const double xi = (i + rng.next_double()) / n;
      at.push_back(fog_sample_lit_segment(medium_, ray.origin, ray.direction, s, in.t0, in.t1, xi));
    }
    at.push_back(in.t1);
    shown.resize(at.size());
    for (size_t i = 0; i < at.size(); ++i) shown[i] = visible(ray, at[i], toward_sun, result);
    // Walk the probes; bisect every change of V between neighbours.
    double piece_start = in.t0;
    for (size_t i = 0; i + 1 < at.size(); ++i) {
      if (shown[i] == shown[i + 1]) continue;
      double lo = at[i], hi = at[i + 1];
      for (int step = 0; step < bisections; ++step) {
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) break;  // as fine as t resolves
        (visible(ray, mid, toward_sun, result) == shown[i] ? lo : hi) = mid;
      }
      const double transition = 0.5 * (lo + hi);
      if (shown[i] > 0) append_lit(&lit, piece_start, transition);
      piece_start = transition;
    }
    if (shown.back() > 0) append_lit(&lit, piece_start, in.t1);
  }
  append_lit(&lit, t, b);
  return integrate_lit(medium_, ray.origin, ray.direction, s, a, lit);
}

FogRayResult FogIntegrator::integrate(const glm::dvec3& origin, const glm::dvec3& direction, double t_end,
                                      SampleRng& rng) const {
  FogRayResult r;
  // T(0, t_end) and the sky's share (L_sky/2, never shadowed): closed forms, to the end.
  r.transmittance = fog_transmittance(medium_, origin, direction, 0, t_end);
  r.inscatter = (0.5 * fog_shadowed_segment(medium_, origin, direction, 0, t_end, 0).sky) * sky_;
  if (!sunlit_) return r;
  const FogClip clip = fog_clip_to_top(medium_, origin, direction, 0, t_end);
  if (clip.empty) return r;
  // [0, a] lies above the top: no fog there, so τ(0, a) = 0 and depths below start at a.
  const double a = clip.t0;
  double b = clip.t1;
  const double cut = fog_distance_at_depth(medium_, origin, direction, a, kFogNegligibleDepth);
  if (cut < b) b = cut, r.terminated_early = true;
  b = std::min(b, kFogFar);
  if (!(b > a)) return r;
  const CameraRay ray{origin, direction};
  const glm::dvec3& s = sun_.direction;

  // Where a shadow can fall at all: finite even when [a, b] is not (height fog without a
  // top, a climbing ray: b = kFogFar), so no probe lies far beyond the plants.
  const FogInterval shade = shadow_range(ray, a, b);
  std::vector<FogInterval> cones;
  if (mode_ == FogMode::medium || mode_ == FogMode::fast || mode_ == FogMode::refined || mode_ == FogMode::map) {
    if (cones_) {
      cones_->intervals(Ray{origin, direction}, shade.t0, shade.t1, &cones);
      cones = clipped(cones, shade.t0, shade.t1);
    } else if (shade.t1 > shade.t0) {
      cones.push_back(shade);  // no cone set: every point that can be shadowed may be
    }
  }
  double sun = 0;
  switch (mode_) {
    case FogMode::brute: sun = sun_brute(ray, a, b, nullptr, rng, &r); break;
    case FogMode::medium: sun = sun_brute(ray, a, b, &cones, rng, &r); break;
    case FogMode::fast: sun = sun_fast(ray, a, b, cones); break;
    case FogMode::map: sun = sun_map(ray, a, b, cones, rng, &r); break;
    case FogMode::automatic:
    case FogMode::refined: {
      const glm::dvec3 toward_sun = disc_direction(rng);
      sun = sun_refined(ray, a, b, cones, steps_, kRefinedBisections, toward_sun, rng, &r);
      break;
    }
    case FogMode::reference: {
      std::vector<FogInterval> whole;
      if (shade.t1 > shade.t0) whole.push_back(shade);
      const int grid = sun_.angular_radius_rad > 0 ? 4 : 1;  // kReferenceDiscSamples = grid²
      const double one_minus_cos = 2 * std::pow(std::sin(0.5 * sun_.angular_radius_rad), 2);
      for (int i = 0; i < grid; ++i)
        for (int j = 0; j < grid; ++j) {
          glm::dvec3 toward_sun = s;
          if (grid > 1) {  // stratified over the disc: cos θ and φ in a 4×4 grid, jittered
            const double cos_t = 1 - (i + rng.next_double()) / grid * one_minus_cos;
            const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
            const double phi = 2 * std::numbers::pi * (j + rng.next_double()) / grid;
            toward_sun = glm::normalize(cos_t * s + sin_t * (std::cos(phi) * sun_frame_.e0 +
                                                             std::sin(phi) * sun_frame_.e1));
          }
          sun += sun_refined(ray, a, b, whole, kReferenceProbesPerStep * steps_, kReferenceBisections, toward_sun,
                             rng, &r);
        }
      sun /= grid * grid;
      break;
    }
  }
  const double phase = fog_phase_schlick(medium_.schlick_k, glm::dot(direction, s));
  r.inscatter += (sun * phase) * sun_.radiance;
  return r;
}

void ConeSetFogSource::intervals(const Ray& ray, double t_min, double t_max, std::vector<FogInterval>* out) const {
  thread_local std::vector<ConeInterval> found;
  set_.intervals(ray, t_min, t_max, &found);
  out->clear();
  for (const ConeInterval& i : found) out->push_back({i.t_enter, i.t_exit});
}

}  // namespace sylva
