// Tests for core/light/fog.h: the medium of docs/spec/fog.md and its closed forms.
//
// FogHand.*  hand-computed values (each derivation in a comment) and the phase function's
//            sign convention and normalisation.
// FogStiff.* the stiff matrix: σ_t from 1e-12 to 1e3 per metre, h = 0, 1e-9, 1; horizontal,
//            vertical, oblique, near-horizontal and sun-parallel (d_y = s_y) rays; segments
//            from 1 mm to unbounded; with and without a top; eyes and grounds at 10⁶ m;
//            the sun from the zenith to 1e-3 above the horizon. Each closed form is compared
//            with a long-double reference computed differently: optical depths by global
//            adaptive Gauss–Kronrod (7–15) quadrature of σ_t·ρ(y(t)) itself; the lit-segment
//            integrals by the same quadrature of σ_s(x(t))·T(0,t)·T_sun(x(t)) with the
//            optical depths inside it in long-double closed form (which the first group
//            checks against quadrature too).
// FogLimits.* no NaN, no infinity where a finite value is due, no subnormal output, over a
//            fuzz of extreme inputs (t = ∞, σ = 0, s_y = 1e-310, τ > 800, …).
//
// Error measure: a result x against its reference r is within bound when
//   |x − r| <= kRelative·(1 + E)·|r| + 1e-300,   kRelative = 4e-15
// with E the optical depth whose exponential the result carries (the condition number of
// e^{−E} with respect to a relative error in E is E): 0 for τ itself, τ for T, the depth
// eye → x → sun at the segment's brighter end for the sun term (case_sun_depth),
// depth_to_t0 for the sky term. The figures measured are printed by
// the two quadrature tests and recorded in docs/fog.md. Results below 1e-300 count as
// 0 (fog.h flushes them), and T beyond kFogMaxDepth must be exactly 0.
#include "core/light/fog.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <limits>
#include <map>
#include <queue>
#include <random>
#include <vector>

namespace sylva {
namespace {

using LD = long double;
constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// The stated bound: relative error per unit (1 + E).
constexpr double kRelative = 4e-15;

// ---- Long-double reference: global adaptive Gauss–Kronrod 7-15 ------------------------

// QUADPACK's qk15 nodes and weights (33 digits).
constexpr LD kXgk[8] = {0.991455371120812639206854697526329L, 0.949107912342758524526189684047851L,
                        0.864864423359769072789712788640926L, 0.741531185599394439863864773280788L,
                        0.586087235467691130294144845693013L, 0.405845151377397166906606412076961L,
                        0.207784955007898467600689403773245L, 0.0L};
constexpr LD kWgk[8] = {0.022935322010529224963732008058970L, 0.063092092629978553290700663189204L,
                        0.104790010322250183839876322541518L, 0.140653259715525918745189590510238L,
                        0.169004726639267902826583426598550L, 0.190350578064785409913256402421014L,
                        0.204432940075298892414161999234649L, 0.209482141084727828012999174891714L};
constexpr LD kWg[4] = {0.129484966168869693270611432679082L, 0.279705391489276667901467771423780L,
                       0.381830050505118944950369775488975L, 0.417959183673469387755102040816327L};

struct Piece {
  LD a, b, value, error;
  bool operator<(const Piece& o) const { return error < o.error; }
};

// One Gauss–Kronrod 7-15 panel. Its error estimate |K − G| counts as 0 once it is below
// `tolerance` of the panel's ∫|f| (QUADPACK's round-off rule, simplified), so the refinement
// below stops instead of chasing the integrand's own rounding noise: e^{−E} evaluated in long
// double carries a relative noise of ~ε·E, 4e-16 at E = 3571.
Piece gauss_kronrod(const std::function<LD(LD)>& f, LD a, LD b, LD tolerance) {
  const LD centre = (a + b) / 2, half = (b - a) / 2;
  const LD fc = f(centre);
  LD kronrod = fc * kWgk[7], gauss = fc * kWg[3], magnitude = std::abs(fc) * kWgk[7];
  for (int i = 0; i < 7; ++i) {
    const LD dx = half * kXgk[i];
    const LD fl = f(centre - dx), fr = f(centre + dx);
    kronrod += kWgk[i] * (fl + fr);
    magnitude += kWgk[i] * (std::abs(fl) + std::abs(fr));
    if (i % 2 == 1) gauss += kWg[i / 2] * (fl + fr);
  }
  LD error = std::abs((kronrod - gauss) * half);
  if (error <= tolerance * magnitude * std::abs(half)) error = 0;
  return {a, b, kronrod * half, error};
}

// ∫_a^b f over the given breakpoints (inside [a, b]), 16 equal pieces and pieces crowding
// both ends geometrically (2^-k of the length, k = 1..40), so that an integrand concentrated
// within 1e-12 of an end is seen by the first pass; then the piece with the largest error
// estimate is halved until the total error is below `tolerance` of the total (long
// double's ε is 1.1e-19: 1e-18 for integrands of moderate exponents, ~1e-17·(1 + E) for
// e^{−E} integrands).
LD integrate(const std::function<LD(LD)>& f, LD a, LD b, LD tolerance = 1e-18L, std::vector<LD> breaks = {}) {
  std::vector<LD> points{a, b};
  for (LD x : breaks)
    if (x > a && x < b) points.push_back(x);
  const LD length = b - a;
  for (int k = 1; k < 16; ++k) points.push_back(a + length * k / 16);
  for (int k = 1; k <= 40; ++k) {
    points.push_back(a + std::ldexp(length, -k));
    points.push_back(b - std::ldexp(length, -k));
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  std::priority_queue<Piece> queue;
  LD total = 0, error = 0;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const Piece p = gauss_kronrod(f, points[i], points[i + 1], tolerance);
    total += p.value, error += p.error;
    queue.push(p);
  }
  for (int iteration = 0; iteration < 100000 && error > tolerance * std::abs(total); ++iteration) {
    const Piece p = queue.top();
    const LD mid = (p.a + p.b) / 2;
    if (!(mid > p.a && mid < p.b)) break;  // as fine as long double resolves
    queue.pop();
    const Piece left = gauss_kronrod(f, p.a, mid, tolerance), right = gauss_kronrod(f, mid, p.b, tolerance);
    total += left.value + right.value - p.value;
    error += left.error + right.error - p.error;
    queue.push(left);
    queue.push(right);
  }
  return total;
}

// ∫_a^∞ f by t = a + c·s/(1 − s), s in [0, 1); `breaks` are values of t.
LD integrate_to_infinity(const std::function<LD(LD)>& f, LD a, LD c, LD tolerance = 1e-18L,
                         const std::vector<LD>& breaks = {}) {
  std::vector<LD> s_breaks;
  for (LD t : breaks) s_breaks.push_back((t - a) / (c + (t - a)));
  return integrate(
      [&](LD s) {
        const LD one_minus = 1 - s;
        if (!(one_minus > 0)) return 0.0L;
        return f(a + c * s / one_minus) * c / (one_minus * one_minus);
      },
      0, 1, tolerance, s_breaks);
}

// The medium in long double, straight from docs/spec/fog.md: heights above the ground.
struct RefMedium {
  LD sigma_s, sigma_t, h, top;  // top: height of the top above the ground (inf: none)
};

RefMedium ref_of(const FogMedium& m) {
  return {LD(m.sigma_s), LD(m.sigma_t), LD(m.height_falloff), LD(m.top) - LD(m.ground)};
}

LD ref_density(const RefMedium& m, LD height) { return height > m.top ? 0.0L : std::exp(-m.h * height); }

// The part of [a, b] below the top for a ray from height y0 with vertical component dy.
bool ref_clip(const RefMedium& m, LD y0, LD dy, LD& a, LD& b) {
  if (dy > 0) b = std::min(b, (m.top - y0) / dy);
  if (dy < 0) a = std::max(a, (m.top - y0) / dy);
  if (dy == 0 && y0 > m.top) return false;
  return b > a;
}

// τ(a, b) in long-double closed form, the textbook way: σ_t·e^{−h·y(a)}·(1 − e^{−β L})/β
// with β = h·dy signed (no anchoring at the lower end).
LD ref_depth_closed(const RefMedium& m, LD y0, LD dy, LD a, LD b) {
  if (m.sigma_t == 0 || !ref_clip(m, y0, dy, a, b)) return 0;
  const LD length = b - a, beta = m.h * dy;
  const LD ya = y0 + a * dy;
  const LD integral = beta == 0 ? length : -std::expm1(-beta * length) / beta;
  return m.sigma_t * std::exp(-m.h * ya) * integral;
}

// τ(a, b) by quadrature of σ_t·ρ; +inf for an unbounded homogeneous (along the ray) path.
LD ref_depth_quadrature(const RefMedium& m, LD y0, LD dy, LD a, LD b) {
  if (m.sigma_t == 0 || !ref_clip(m, y0, dy, a, b)) return 0;
  auto f = [&](LD t) { return m.sigma_t * std::exp(-m.h * (y0 + t * dy)); };
  if (std::isinf(b)) {
    if (!(m.h * dy > 0)) return std::numeric_limits<LD>::infinity();
    return integrate_to_infinity(f, a, 1 / (m.h * dy));
  }
  return integrate(f, a, b);
}

LD ref_sun_depth(const RefMedium& m, LD height, LD sy) {
  return ref_depth_closed(m, height, sy, 0, std::numeric_limits<LD>::infinity());
}

struct RefSegment {
  LD sun = 0, sky = 0;
};

// ∫ σ_s(x(t))·T(0,t)·T_sun(x(t)) dt and ∫ σ_s·T(0,t) dt over [a, b] by quadrature.
RefSegment ref_segment(const RefMedium& m, LD y0, LD dy, LD sy, LD a, LD b, LD depth0, LD tolerance) {
  RefSegment out;
  LD ca = a, cb = b;
  if (m.sigma_s == 0 || !ref_clip(m, y0, dy, ca, cb)) return out;
  // One exponential per integrand, log σ_s + log ρ − τ: far down an unbounded descending
  // ray ρ overflows while T(0,t) underflows, and only their product is finite.
  const LD log_sigma = std::log(m.sigma_s) - depth0;
  auto sky = [&](LD t) {
    const LD height = y0 + t * dy;
    if (height > m.top) return 0.0L;
    return std::exp(log_sigma - m.h * height - ref_depth_closed(m, y0, dy, ca, t));
  };
  auto sun = [&](LD t) {
    const LD height = y0 + t * dy;
    if (!(sy > 0) || height > m.top) return 0.0L;
    return std::exp(log_sigma - m.h * height - ref_depth_closed(m, y0, dy, ca, t) - ref_sun_depth(m, height, sy));
  };
  // Breakpoints where τ(t0, t) passes 2^-8 … 2^12 (bisection; they only guide the
  // quadrature): an integrand that ρ growing down a descending ray cuts off
  // double-exponentially is then resolved wherever it lies.
  std::vector<LD> breaks;
  const LD reach = std::isinf(cb) ? std::numeric_limits<LD>::max() : cb;
  for (int k = -8; k <= 12; ++k) {
    const LD level = std::ldexp(1.0L, k);
    LD lo = ca, hi = std::isinf(cb) ? ca + 1 : cb;
    while (std::isinf(cb) && ref_depth_closed(m, y0, dy, ca, hi) < level && hi < 1e30L) hi = ca + 2 * (hi - ca);
    if (!(ref_depth_closed(m, y0, dy, ca, std::min(hi, reach)) >= level)) break;
    for (int i = 0; i < 200 && hi - lo > 1e-18L * std::abs(hi); ++i) {
      const LD mid = (lo + hi) / 2;
      (ref_depth_closed(m, y0, dy, ca, mid) < level ? lo : hi) = mid;
    }
    breaks.push_back(lo);
  }
  if (std::isinf(cb)) {
    // Decay scale: the larger of the density's scale along the ray and its optical scale.
    const LD rate = m.sigma_t * ref_density(m, y0 + ca * dy) + m.h * std::abs(dy);
    const LD c = 1 / rate;
    out.sky = integrate_to_infinity(sky, ca, c, tolerance, breaks);
    out.sun = integrate_to_infinity(sun, ca, c, tolerance, breaks);
  } else {
    out.sky = integrate(sky, ca, cb, tolerance, breaks);
    out.sun = integrate(sun, ca, cb, tolerance, breaks);
  }
  return out;
}

// |x − r| within the stated bound for a result built from optical depths up to `depth`.
::testing::AssertionResult close(double x, LD r, LD depth, double relative = kRelative) {
  const LD e = std::min<LD>(depth, 1e6L);
  const LD allowed = relative * (1 + e) * std::abs(r) + 1e-300L;
  if (std::isinf(r) && std::isinf(x)) return ::testing::AssertionSuccess();
  if (std::isfinite(x) && std::abs(LD(x) - r) <= allowed) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << x << ", reference " << double(r) << ", relative error "
                                       << double(std::abs(LD(x) - r) / std::abs(r)) << " > "
                                       << double(allowed / std::abs(r));
}

glm::dvec3 unit(glm::dvec3 v) { return glm::normalize(v); }

// ---- Hand-computed values -------------------------------------------------------------

TEST(FogHand, PhaseIsIsotropicAtZeroAsymmetry) {
  for (double c : {-1.0, -0.3, 0.0, 0.7, 1.0}) EXPECT_DOUBLE_EQ(fog_phase_schlick(fog_schlick_k(0), c), 1 / (4 * kPi));
}

TEST(FogHand, PositiveAsymmetryIsBrightestLookingTowardTheSun) {
  // cos θ = d·s with d from the eye into the scene and s toward the sun: looking at the sun
  // is d = s, cos θ = +1.
  const glm::dvec3 s = unit({0.2, 0.3, -1});
  const double k = fog_schlick_k(0.6);
  const double toward = fog_phase_schlick(k, glm::dot(s, s));
  const double away = fog_phase_schlick(k, glm::dot(-s, s));
  EXPECT_GT(toward, 10 * away);
  // k(0.5) = 0.775 − 0.06875 = 0.70625; p(1) = (1 − k²)/(4π(1 − k)²) = (1 + k)/(4π(1 − k)).
  EXPECT_DOUBLE_EQ(fog_schlick_k(0.5), 0.70625);
  EXPECT_NEAR(fog_phase_schlick(0.70625, 1), 1.70625 / (4 * kPi * 0.29375), 1e-15);
  EXPECT_NEAR(fog_phase_schlick(0.70625, -1), 0.29375 / (4 * kPi * 1.70625), 1e-16);
  // g < 0 scatters back: brightest with the sun behind the eye.
  EXPECT_LT(fog_phase_schlick(fog_schlick_k(-0.6), 1), fog_phase_schlick(fog_schlick_k(-0.6), -1));
}

TEST(FogHand, PhaseIntegratesToOneOverTheSphere) {
  for (double g : {-0.9, -0.5, 0.0, 0.3, 0.6, 0.9, 0.938}) {
    const LD k = fog_schlick_k(g);
    const LD total =
        2 * kPi * integrate([&](LD c) { return LD(fog_phase_schlick(double(k), double(c))); }, -1, 1, 1e-15L);
    EXPECT_NEAR(double(total), 1.0, 1e-13) << "g = " << g;
  }
}

TEST(FogHand, MaxAsymmetryIsWhereSchlicksKReachesOne) {
  EXPECT_LT(fog_schlick_k(kFogMaxAbsG), 1.0);
  EXPECT_GT(fog_schlick_k(kFogMaxAbsG + 1e-9), 1.0);
  EXPECT_GT(fog_schlick_k(-kFogMaxAbsG), -1.0);
  EXPECT_NEAR(kFogMaxAbsG, (std::sqrt(2.5025) - 0.55) / 1.1, 1e-12);
}

TEST(FogHand, HomogeneousSkyTermIsAlbedoTimesOneMinusTransmittance) {
  // σ_s = 0.05, σ_a = 0.005, L = 20: ∫₀^L σ_s e^{−σ_t t} dt = σ_s/σ_t·(1 − e^{−σ_t L}).
  const FogMedium m = fog_medium(0.05, 0.005, 0.6, 0, 0);
  const glm::dvec3 eye(1, 2, 3), d = unit({1, 0.2, -0.5}), s = unit({0.4, 1, 0.2});
  const FogSegment seg = fog_lit_segment(m, eye, d, s, 0, 20, 0);
  EXPECT_NEAR(seg.sky, 0.05 / 0.055 * (1 - std::exp(-0.055 * 20)), 1e-15);
  EXPECT_NEAR(seg.depth, 0.055 * 20, 1e-15);
  // Without a top the sunlight never reaches the fog: T_sun = 0 (fog.h).
  EXPECT_EQ(seg.sun, 0.0);
  EXPECT_EQ(fog_sun_transmittance(m, eye, s), 0.0);
  EXPECT_EQ(fog_transmittance(m, eye, d, 0, kInf), 0.0);
}

TEST(FogHand, SunParallelRayInHomogeneousFogHasAConstantIntegrand) {
  // d = s = +Y from height 2 under a top at 30: T(0,t)·T_sun(x(t)) = e^{−σ_t t}·e^{−σ_t(28 − t)}
  // = e^{−28 σ_t} for every t < 28, so ∫₀^L σ_s … = σ_s·L·e^{−28 σ_t} (d_y = s_y: κ = 0).
  const FogMedium m = fog_medium(0.05, 0.005, 0.6, 0, 0, 30);
  const glm::dvec3 eye(0, 2, 0), up(0, 1, 0);
  const FogSegment seg = fog_lit_segment(m, eye, up, up, 0, 10, 0);
  EXPECT_NEAR(seg.sun, 0.05 * 10 * std::exp(-28 * 0.055), 1e-16);
  // Beyond the top nothing scatters: the segment [0, 100] counts only [0, 28].
  EXPECT_NEAR(fog_lit_segment(m, eye, up, up, 0, 100, 0).sun, 0.05 * 28 * std::exp(-28 * 0.055), 1e-16);
  EXPECT_NEAR(fog_optical_depth(m, eye, up, 0, 100), 28 * 0.055, 1e-15);
  EXPECT_NEAR(fog_sun_transmittance(m, eye, up), std::exp(-28 * 0.055), 1e-16);
}

TEST(FogHand, HorizontalRayUnderZenithSunInHomogeneousFog) {
  // T_sun = e^{−σ_t (top − y)} along a horizontal ray: sun = albedo·e^{−σ_t(top−y)}·(1 − e^{−σ_t L}).
  const FogMedium m = fog_medium(0.1, 0.02, 0, 0, 5, 35);
  const glm::dvec3 eye(0, 7, 0), d(1, 0, 0), up(0, 1, 0);
  const double expected = 0.1 / 0.12 * std::exp(-0.12 * 28) * -std::expm1(-0.12 * 40);
  EXPECT_NEAR(fog_lit_segment(m, eye, d, up, 0, 40, 0).sun, expected, 1e-16);
  // Starting further along: T(0, t0) = e^{−depth_to_t0} multiplies both terms.
  const FogSegment later = fog_lit_segment(m, eye, d, up, 10, 50, 0.12 * 10);
  EXPECT_NEAR(later.sun, expected * std::exp(-1.2), 1e-16);
}

TEST(FogHand, HeightFogClosedForms) {
  const double sigma = 0.2, h = 0.5;
  const FogMedium m = fog_medium(sigma, 0, 0, h, 1);
  // Straight up from the ground to infinity: ∫₀^∞ σ e^{−h t} dt = σ/h.
  EXPECT_NEAR(fog_optical_depth(m, {0, 1, 0}, {0, 1, 0}, 0, kInf), sigma / h, 1e-16);
  // Horizontal at 3 m above the ground: σ e^{−3h}·L.
  EXPECT_NEAR(fog_optical_depth(m, {0, 4, 0}, {0, 0, 1}, 2, 9), sigma * std::exp(-3 * h) * 7, 1e-16);
  // Toward a zenith sun from 3 m: σ e^{−3h}/h.
  EXPECT_NEAR(fog_sun_optical_depth(m, {5, 4, 5}, {0, 1, 0}), sigma * std::exp(-3 * h) / h, 1e-16);
  // Horizontal camera ray, zenith sun: σ_s = u constant, T_sun = e^{−u/h}:
  // sun = e^{−u/h}·(1 − e^{−u L}) (albedo 1).
  const double u = sigma * std::exp(-3 * h);
  EXPECT_NEAR(fog_lit_segment(m, {0, 4, 0}, {1, 0, 0}, {0, 1, 0}, 0, 7, 0).sun,
              std::exp(-u / h) * -std::expm1(-u * 7), 1e-16);
  // Unbounded horizontal ray in height fog: τ = ∞.
  EXPECT_EQ(fog_transmittance(m, {0, 4, 0}, {1, 0, 0}, 0, kInf), 0.0);
}

TEST(FogHand, SunBelowTheHorizon) {
  const FogMedium m = fog_medium(0.05, 0.01, 0.5, 0.1, 0, 40);
  const glm::dvec3 below = unit({1, -0.1, 0}), level(1, 0, 0);
  EXPECT_EQ(fog_lit_segment(m, {0, 3, 0}, {0, 0, 1}, below, 0, 20, 0).sun, 0.0);
  EXPECT_EQ(fog_lit_segment(m, {0, 3, 0}, {0, 0, 1}, level, 0, 20, 0).sun, 0.0);
  EXPECT_EQ(fog_sun_transmittance(m, {0, 3, 0}, below), 0.0);
  EXPECT_EQ(fog_sun_transmittance(m, {0, 3, 0}, level), 0.0);
  // Above the top a level sun is not attenuated; a descending one enters the fog for ever.
  EXPECT_EQ(fog_sun_transmittance(m, {0, 41, 0}, level), 1.0);
  EXPECT_EQ(fog_sun_transmittance(m, {0, 41, 0}, below), 0.0);
}

TEST(FogHand, TopClipsEverySegment) {
  const FogMedium m = fog_medium(0.3, 0.1, 0, 0, 0, 10);
  // A ray from 20 m going down at 45°: in the fog from t = 10√2 on.
  const glm::dvec3 eye(0, 20, 0), d = unit({1, -1, 0});
  const FogClip clip = fog_clip_to_top(m, eye, d, 0, 30);
  EXPECT_FALSE(clip.empty);
  EXPECT_NEAR(clip.t0, 10 * std::sqrt(2.0), 1e-13);
  EXPECT_EQ(clip.t1, 30);
  EXPECT_NEAR(fog_optical_depth(m, eye, d, 0, 30), 0.4 * (30 - 10 * std::sqrt(2.0)), 1e-13);
  EXPECT_TRUE(fog_clip_to_top(m, eye, {1, 0, 0}, 0, kInf).empty);
  EXPECT_EQ(fog_optical_depth(m, eye, {0, 1, 0}, 0, kInf), 0.0);
  EXPECT_EQ(fog_density(m, 10.5), 0.0);
  EXPECT_EQ(fog_density(m, 9.5), 1.0);
}

TEST(FogHand, TransmittanceUnderflowsToExactZeroNotToDenormals) {
  EXPECT_EQ(fog_transmittance_of_depth(kFogMaxDepth + 1), 0.0);
  EXPECT_EQ(fog_transmittance_of_depth(kInf), 0.0);
  EXPECT_EQ(std::fpclassify(fog_transmittance_of_depth(kFogMaxDepth)), FP_NORMAL);
  EXPECT_NEAR(fog_transmittance_of_depth(150) / std::exp(-150.0L), 1.0, 1e-15);
}

TEST(FogHand, ExprelAndLnrelAreAccurateThroughZero) {
  for (double x : {0.0, 1e-300, -1e-20, 1e-12, -3e-5, 9.9e-5, 1.01e-4, -0.5, 2.0, -40.0}) {
    const LD ref = x == 0 ? 1.0L : std::expm1(LD(x)) / LD(x);
    EXPECT_NEAR(fog_exprel(x) / double(ref), 1.0, 3e-16) << x;
    if (x < 1) {
      const LD lref = x == 0 ? 1.0L : -std::log1p(-LD(x)) / LD(x);
      EXPECT_NEAR(fog_lnrel(x) / double(lref), 1.0, 3e-16) << x;
    }
  }
  EXPECT_EQ(fog_lnrel(1), kInf);
  // The cancellation the brief forbids: (1 − e^{−σΔ})/σ at σ = 1e-12 keeps 4 digits; this keeps 16.
  EXPECT_NEAR(fog_exp_integral(1, 1e-12), 1 - 0.5e-12, 1e-28);
  EXPECT_EQ(fog_exp_integral(kInf, 0.25), 4.0);
  EXPECT_EQ(fog_exp_integral(kInf, 0), kFogFar);
  EXPECT_EQ(fog_exp_integral(0, kInf), 0.0);
}

// ---- The stiff matrix ------------------------------------------------------------------

struct Case {
  FogMedium medium;
  glm::dvec3 eye, direction, sun;
  double t0, t1, depth0;
  std::string name;
};

std::vector<Case> stiff_cases() {
  std::vector<Case> cases;
  const double sigmas[] = {1e-12, 1e-6, 0.05, 1, 1e3};
  const double falloffs[] = {0, 1e-9, 1};
  struct Dir {
    glm::dvec3 v;
    const char* name;
  };
  const Dir dirs[] = {{{1, 0, 0}, "horizontal"},
                      {{0, 1, 0}, "up"},
                      {{0, -1, 0}, "down"},
                      {unit({1, 0.3, 0.2}), "oblique up"},
                      {unit({1, -0.3, 0.2}), "oblique down"},
                      {unit({1, 1e-9, 0}), "near-horizontal"}};
  const glm::dvec3 suns[] = {{0, 1, 0}, unit({1, 0.3, 0.2}), unit({1, 1e-3, 0.5}), unit({-1, 0.05, 0})};
  struct Span {
    double t0, t1;
  };
  const Span spans[] = {{0, 1e-3}, {0.5, 2}, {0, 100}, {3, kInf}};
  const double offsets[] = {0, 1e6};
  for (double sigma : sigmas)
    for (double h : falloffs)
      for (int top = 0; top < 2; ++top)
        for (double offset : offsets)
          for (const Dir& d : dirs)
            for (const glm::dvec3& s : suns)
              for (const Span& span : spans) {
                // An eye 2 m above the ground (at the offset), a top 40 m above it. Sun-parallel
                // rays: the oblique-up direction with the second sun is d_y = s_y exactly.
                const double ground = offset;
                const FogMedium m = fog_medium(0.8 * sigma, 0.2 * sigma, 0.6, h, ground, top ? ground + 40 : kInf);
                const glm::dvec3 eye(offset + 0.25, ground + 2, offset - 0.5);
                char name[200];
                std::snprintf(name, sizeof name, "σ_t=%g h=%g top=%s offset=%g dir=%s sun=(%.3g,%.3g,%.3g) t=[%g,%g]",
                              sigma, h, top ? "40" : "none", offset, d.name, s.x, s.y, s.z, span.t0, span.t1);
                cases.push_back({m, eye, d.v, s, span.t0, span.t1, 0, name});
              }
  // An eye above the top looking down into it, and a segment starting after a thick stretch.
  const FogMedium layer = fog_medium(0.04, 0.01, 0.6, 0.2, 0, 30);
  cases.push_back({layer, {0, 60, 0}, unit({1, -0.5, 0}), unit({0.3, 1, 0}), 0, 200, 0, "from above the top"});
  cases.push_back({layer, {0, 1, 0}, unit({1, 0.01, 0}), unit({0.3, 1, 0}), 10, 400, 2.5, "depth_to_t0 = 2.5"});
  return cases;
}

// The optical depth E of the error bound for a segment's sun term: eye → x → sun at the
// segment's brighter end, min(E(t0), E(t1)) (where the integrand is largest, and where the
// long-double reference's own e^{−E} carries its noise ε·E), capped at 800 (beyond it every
// term is below 1e-300 of the largest). The sky term's E is depth_to_t0.
LD case_sun_depth(const Case& c) {
  const RefMedium m = ref_of(c.medium);
  const LD y0 = LD(c.eye.y) - LD(c.medium.ground), dy = c.direction.y;
  LD ca = c.t0, cb = c.t1;
  if (!ref_clip(m, y0, dy, ca, cb)) return c.depth0;
  const LD at_start = ref_sun_depth(m, y0 + ca * dy, c.sun.y);
  LD at_end = std::numeric_limits<LD>::infinity();
  if (std::isfinite(cb)) at_end = ref_depth_closed(m, y0, dy, ca, cb) + ref_sun_depth(m, y0 + cb * dy, c.sun.y);
  return std::min<LD>(c.depth0 + std::min(at_start, at_end), 800);
}

// The worst errors of one group, printed for docs/fog.md at the end of its test.
struct Worst {
  double relative = 0;       // max |x − r| / |r|
  double per_depth = 0;      // max |x − r| / (|r| (1 + E))
  std::string where;
  void print(const char* name) const {
    std::printf("[ fog accuracy ] %-15s max relative error %.2e, max per (1 + E) %.2e at %s\n", name, relative,
                per_depth, where.c_str());
  }
  void add(double x, LD r, LD depth, const std::string& name) {
    if (!(std::abs(r) > 1e-290L) || std::isinf(r)) return;
    const double e = double(std::abs(LD(x) - r) / std::abs(r));
    relative = std::max(relative, e);
    const double p = e / double(1 + std::min<LD>(depth, 1e6L));
    if (p > per_depth) per_depth = p, where = name;
  }
};

TEST(FogStiff, OpticalDepthMatchesQuadrature) {
  Worst worst_depth;
  for (const Case& c : stiff_cases()) {
    const RefMedium m = ref_of(c.medium);
    const LD y0 = LD(c.eye.y) - LD(c.medium.ground);
    const LD ref = ref_depth_quadrature(m, y0, c.direction.y, c.t0, c.t1);
    const double tau = fog_optical_depth(c.medium, c.eye, c.direction, c.t0, c.t1);
    ASSERT_FALSE(std::isnan(tau)) << c.name;
    if (std::isinf(ref)) {
      EXPECT_EQ(fog_transmittance(c.medium, c.eye, c.direction, c.t0, c.t1), 0.0) << c.name;
      continue;
    }
    // τ itself: relative error independent of its size.
    EXPECT_TRUE(close(tau, ref, 0)) << c.name;
    // The long-double closed form the segment reference uses agrees with quadrature.
    const LD closed = ref_depth_closed(m, y0, c.direction.y, c.t0, c.t1);
    EXPECT_LE(std::abs(closed - ref), 1e-17L * ref) << c.name;
    // T = e^{−τ}, including τ > 100 and beyond kFogMaxDepth (exactly 0 there).
    const double T = fog_transmittance(c.medium, c.eye, c.direction, c.t0, c.t1);
    if (ref > kFogMaxDepth) {
      EXPECT_EQ(T, 0.0) << c.name;
    } else {
      EXPECT_TRUE(close(T, std::exp(-ref), ref)) << c.name;
    }
    worst_depth.add(tau, ref, 0, c.name);
  }
  worst_depth.print("optical depth");
  EXPECT_GT(worst_depth.relative, 0.0);  // measured at all
}

TEST(FogStiff, LitSegmentMatchesQuadrature) {
  // The reference depends on heights above the ground only, so the 10⁶ m variant of a case
  // shares its offset-0 twin's reference (computed once) and must match it just as well.
  std::map<std::array<LD, 10>, RefSegment> references;
  Worst worst_sun, worst_sky;
  int compared = 0, thick = 0;
  for (const Case& c : stiff_cases()) {
    const RefMedium m = ref_of(c.medium);
    const LD y0 = LD(c.eye.y) - LD(c.medium.ground);
    const LD depth = case_sun_depth(c), sky_depth = c.depth0;
    const std::array<LD, 10> key{m.sigma_s, m.sigma_t, m.h, m.top, y0, c.direction.y, c.sun.y, c.t0, c.t1, c.depth0};
    auto found = references.find(key);
    if (found == references.end()) {
      const RefSegment ref = ref_segment(m, y0, c.direction.y, c.sun.y, c.t0, c.t1, c.depth0, 1e-17L * (1 + depth));
      // The quadrature checked against an identity it knows nothing of: ∫σ_s T(0,t) dt =
      // albedo·T(0,t0)·(1 − T(t0,t1)) for any profile.
      const LD identity = m.sigma_s / m.sigma_t * std::exp(-LD(c.depth0)) *
                          -std::expm1(-ref_depth_closed(m, y0, c.direction.y, c.t0, c.t1));
      EXPECT_LE(std::abs(ref.sky - identity), 1e-16L * (1 + depth) * identity + 1e-300L) << "reference, " << c.name;
      found = references.emplace(key, ref).first;
    }
    const RefSegment& ref = found->second;
    const FogSegment seg = fog_lit_segment(c.medium, c.eye, c.direction, c.sun, c.t0, c.t1, c.depth0);
    ASSERT_TRUE(std::isfinite(seg.sun) && std::isfinite(seg.sky)) << c.name;
    EXPECT_TRUE(close(seg.sky, ref.sky, sky_depth)) << "sky, " << c.name;
    EXPECT_TRUE(close(seg.sun, ref.sun, depth)) << "sun, " << c.name;
    worst_sun.add(seg.sun, ref.sun, depth, c.name);
    worst_sky.add(seg.sky, ref.sky, sky_depth, c.name);
    ++compared;
    if (ref_depth_closed(m, y0, c.direction.y, c.t0, c.t1) > 800 && ref.sun > 1e-290L) ++thick;
  }
  EXPECT_GT(thick, 20);  // the matrix does reach τ(t0, t1) > 800 with a non-zero answer
  EXPECT_GT(compared, 2000);
  worst_sun.print("sun in-scatter");
  worst_sky.print("sky in-scatter");
}

TEST(FogStiff, DistanceAtDepthInvertsOpticalDepth) {
  // Reference in long double: τ(t0, t0 + s) = σ0·(1 − e^{−β s})/β, β = h·d_y, so
  // s = −log1p(−β τ/σ0)/β. A double t carries its own rounding, ulp(t), on top.
  int compared = 0;
  for (const Case& c : stiff_cases()) {
    const FogClip clip = fog_clip_to_top(c.medium, c.eye, c.direction, c.t0, c.t1);
    if (clip.empty) continue;
    const RefMedium m = ref_of(c.medium);
    const LD y0 = LD(c.eye.y) - LD(c.medium.ground);
    const LD sigma0 = m.sigma_t * std::exp(-m.h * (y0 + LD(clip.t0) * c.direction.y));
    const LD beta = m.h * c.direction.y;
    const double total = fog_optical_depth(c.medium, c.eye, c.direction, clip.t0, clip.t1);
    for (double share : {0.0, 1e-9, 0.3, 0.999}) {
      const double depth = share * std::min(total, 1e4);
      const double t = fog_distance_at_depth(c.medium, c.eye, c.direction, clip.t0, depth);
      ASSERT_FALSE(std::isnan(t)) << c.name;
      if (depth == 0) {
        EXPECT_EQ(t, clip.t0);
        continue;
      }
      const LD s = beta == 0 ? depth / sigma0 : -std::log1p(-beta * depth / sigma0) / beta;
      const LD t_ref = clip.t0 + s;
      EXPECT_LE(std::abs(LD(t) - t_ref), 1e-13L * s + 4e-16L * std::abs(t_ref)) << c.name << " share " << share;
      ++compared;
    }
    // Past the ray's whole remaining optical depth: +inf. Finite only for a climbing ray
    // that leaves through the top or into ever thinner height fog.
    const double remaining = fog_optical_depth(c.medium, c.eye, c.direction, clip.t0, kInf);
    if (c.direction.y > 0 && (c.medium.height_falloff > 0 || std::isfinite(c.medium.top))) {
      EXPECT_EQ(fog_distance_at_depth(c.medium, c.eye, c.direction, clip.t0, 1.01 * remaining + 1e-300), kInf)
          << c.name;
    }
  }
  EXPECT_GT(compared, 5000);
}

TEST(FogStiff, SamplingInvertsTheSunlitCumulativeDistribution) {
  int checked = 0;
  for (const Case& c : stiff_cases()) {
    const FogSegment whole = fog_lit_segment(c.medium, c.eye, c.direction, c.sun, c.t0, c.t1, c.depth0);
    if (!(whole.sun > 1e-250)) continue;
    for (double xi : {0.0, 0.1, 0.5, 0.9, 0.999}) {
      const double t = fog_sample_lit_segment(c.medium, c.eye, c.direction, c.sun, c.t0, c.t1, xi);
      ASSERT_GE(t, c.t0) << c.name;
      ASSERT_LE(t, c.t1) << c.name;
      const double part = fog_lit_segment(c.medium, c.eye, c.direction, c.sun, c.t0, t, c.depth0).sun;
      EXPECT_NEAR(part / whole.sun, xi, 1e-9) << c.name << " xi " << xi;
    }
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// ---- Limits: nothing NaN, infinite or subnormal where it must not be --------------------

bool tame(double x) { return std::isfinite(x) && x >= 0 && std::fpclassify(x) != FP_SUBNORMAL; }

TEST(FogLimits, ExtremeInputsGiveFiniteNonNegativeNormalResults) {
  std::mt19937_64 rng(11);
  const double sigmas[] = {0, 1e-12, 1e-3, 1, 1e3, 1e6};
  const double falloffs[] = {0, 1e-12, 1e-3, 1, 1e3};
  const double tops[] = {kInf, 0, 1e-9, 30, 1e6};
  const double ts[] = {0, 1e-300, 1e-9, 1, 1e6, 1e300, kInf};
  const double ys[] = {-1e-9, 0, 1e-300, 1e-9, 0.5, 1, 1e-310, -1, -1e-310};
  const double heights[] = {-1e-9, 0, 1e-300, 0.5, 29.999, 30, 30.001, 1e3, 1e6, 1e12};
  std::uniform_int_distribution<int> pick(0, 1 << 30);
  auto any = [&](const auto& table) { return table[pick(rng) % std::size(table)]; };
  for (int i = 0; i < 200000; ++i) {
    const double ground = pick(rng) % 2 ? 0.0 : 1e6;
    const FogMedium m = fog_medium(any(sigmas), any(sigmas), 0.5, any(falloffs), ground, ground + any(tops));
    const double dy = any(ys), sy = any(ys);
    const glm::dvec3 d(std::sqrt(std::max(0.0, 1 - dy * dy)), dy, 0);
    const glm::dvec3 s(0, sy, std::sqrt(std::max(0.0, 1 - sy * sy)));
    const glm::dvec3 eye(0, ground + any(heights), 0);
    double t0 = any(ts), t1 = any(ts);
    if (t0 > t1) std::swap(t0, t1);
    if (std::isinf(t0)) t0 = 0;
    const double depth0 = pick(rng) % 3 == 0 ? 800.0 : 0.0;
    char what[400];
    std::snprintf(what, sizeof what, "#%d: σ_s %a σ_a %a h %a ground %a top %a eye.y %a d.y %a s.y %a t [%a, %a] τ0 %g",
                  i, m.sigma_s, m.sigma_a, m.height_falloff, m.ground, m.top, eye.y, d.y, s.y, t0, t1, depth0);
    const double tau = fog_optical_depth(m, eye, d, t0, t1);
    ASSERT_TRUE(!std::isnan(tau) && tau >= 0 && std::fpclassify(tau) != FP_SUBNORMAL) << what << " τ " << tau;
    ASSERT_TRUE(tame(fog_transmittance(m, eye, d, t0, t1))) << what;
    ASSERT_TRUE(tame(fog_sun_transmittance(m, eye, s))) << what;
    const FogSegment seg = fog_lit_segment(m, eye, d, s, t0, t1, depth0);
    ASSERT_TRUE(tame(seg.sun) && tame(seg.sky)) << what << " sun " << seg.sun << " sky " << seg.sky;
    ASSERT_TRUE(!std::isnan(seg.depth) && seg.depth >= 0) << what;
    ASSERT_LE(seg.sky, 1 + 1e-12) << what;                       // ∫σ_s T ≤ albedo·(1 − T) ≤ 1
    // T_sun ≤ 1, up to the rounding of heights: a segment grazing the top at s_y = 1e-9 sees
    // the top's ulp (3.6e-15 m at 30 m) as an optical depth of ulp·σ_t/s_y toward the sun.
    ASSERT_LE(seg.sun, seg.sky * 1.01 + 1e-300) << what;
    const double t = fog_sample_lit_segment(m, eye, d, s, t0, t1, 0.37);
    ASSERT_TRUE(!std::isnan(t) && t >= t0 && t <= std::max(t0, t1)) << what;
    const double back = fog_distance_at_depth(m, eye, d, t0, 0.5);
    ASSERT_TRUE(!std::isnan(back) && back >= t0) << what;
  }
}

TEST(FogLimits, NoFogAtAllIsTransparentAndDark) {
  const FogMedium m = fog_medium(0, 0, 0.5, 0, 0);
  const FogSegment seg = fog_lit_segment(m, {0, 1, 0}, {1, 0, 0}, {0, 1, 0}, 0, kInf, 0);
  EXPECT_EQ(seg.sun, 0.0);
  EXPECT_EQ(seg.sky, 0.0);
  EXPECT_EQ(seg.depth, 0.0);
  EXPECT_EQ(fog_transmittance(m, {0, 1, 0}, {1, 0, 0}, 0, kInf), 1.0);
  EXPECT_EQ(fog_sun_transmittance(m, {0, 1, 0}, {0, -1, 0}), 1.0);
}

}  // namespace
}  // namespace sylva
