// gl_fog_twin_test.cpp — shaders/fog.glsl against core/light/fog.h, function by function on the
// same inputs (rounded to float first, so only the arithmetic differs): run in a compute
// shader over the stiff matrix of tests/light/fog_test.cpp (σ_t from 1e-12 to 1e3 per
// metre, h = 0, 1e-9, 1, with and without a top, horizontal, vertical, oblique, near-
// horizontal and sun-parallel rays, segments from 1 mm to unbounded, suns from the zenith
// to 1e-3 above the horizon), plus the elementary functions through their limits.
//
// The reference is the C++ in double (itself within 4e-15·(1 + E) of a long-double
// quadrature, fog_test.cpp). The bound for a GLSL result x against the C++ r:
//   |x − r| <= kFloatRelative·(1 + E)·|r| + kFloatFloor
// with E the optical depth whose exponential the result carries (as in fog_test.cpp: 0 for
// τ, τ for T, min(E(t0), E(t1)) for the sun term, depth_to_t0 for the sky term), capped at
// fog.glsl's kFogMaxDepth = 80: beyond it the float result is 0 and the double one below
// e^{−80}·(its prefactor). kFloatRelative = 4e-6 (34 float ulps per unit of 1 + E): llvmpipe
// measures at most 8.7e-7 (the worst of each quantity is printed; docs/fog.md records them),
// and a GPU's exp may be looser (the GLSL spec allows 3 + 2|x| ulps, (3 + 2E)·6e-8, which the
// bound covers at every E).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>
#include <limits>
#include <string>
#include <vector>

#include "core/light/fog.h"
#include "core/gl/gl_api.h"
#include "core/gl/gl_shaders.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kFloatRelative = 4e-6;
constexpr double kFloatFloor = 1e-30;   // fog.glsl's kFogFlushBelow
constexpr double kFloatMaxDepth = 80;   // fog.glsl's kFogMaxDepth

// One case per invocation. In (4 vec4): sigma_s, sigma_a, g, h | ground, top, t0, t1 |
// origin, depth0 | direction, xi | sun, depth. Out (4 vec4): phase, τ, T, τ_sun |
// lit.sun, lit.sky, lit.depth, shadowed.sky | clip.t0, clip.t1, clip.empty, T_sun |
// sample(xi), distance_at_depth(t0, depth), density(origin.y), 0.
constexpr int kIn = 5, kOut = 4;
constexpr const char* kTwinMain = R"glsl(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Cases { vec4 cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };
layout(std430, binding = 2) readonly buffer Scalars { vec4 scalars[]; };      // x, length, rate, 0
layout(std430, binding = 3) writeonly buffer ScalarResults { vec4 scalar_results[]; };  // exprel, lnrel, exp_integral, expm1
uniform uint u_count;
uniform uint u_scalar_count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < u_scalar_count) {
    vec4 s = scalars[i];
    scalar_results[i] = vec4(fog_exprel(s.x), fog_lnrel(s.x), fog_exp_integral(s.y, s.z), fog_expm1(s.x));
  }
  if (i >= u_count) return;
  vec4 c0 = cases[5u * i + 0u], c1 = cases[5u * i + 1u], c2 = cases[5u * i + 2u], c3 = cases[5u * i + 3u],
       c4 = cases[5u * i + 4u];
  FogMedium m = fog_medium(c0.x, c0.y, c0.z, c0.w, c1.x, c1.y);
  float t0 = c1.z, t1 = c1.w;
  vec3 origin = c2.xyz, direction = c3.xyz, sun = c4.xyz;
  float depth0 = c2.w, xi = c3.w, depth = c4.w;
  FogSegment lit = fog_lit_segment(m, origin, direction, sun, t0, t1, depth0);
  FogSegment shadowed = fog_shadowed_segment(m, origin, direction, t0, t1, depth0);
  FogClip clip = fog_clip_to_top(m, origin, direction, t0, t1);
  results[4u * i + 0u] = vec4(fog_phase_schlick(m.schlick_k, dot(direction, sun)),
                              fog_optical_depth(m, origin, direction, t0, t1),
                              fog_transmittance(m, origin, direction, t0, t1), fog_sun_optical_depth(m, origin, sun));
  results[4u * i + 1u] = vec4(lit.sun, lit.sky, lit.depth, shadowed.sky);
  results[4u * i + 2u] = vec4(clip.t0, clip.t1, clip.empty ? 1.0 : 0.0, fog_sun_transmittance(m, origin, sun));
  results[4u * i + 3u] = vec4(fog_sample_lit_segment(m, origin, direction, sun, t0, t1, xi),
                              fog_distance_at_depth(m, origin, direction, clip.empty ? t0 : clip.t0, depth),
                              fog_density(m, origin.y), 0.0);
}
)glsl";

GLuint compute_program(std::string* log) {
  const std::string text =
      "#version 450 core\n#line 1 0\n" + std::string(embedded_shader("fog.glsl")) + "#line 1 1\n" + kTwinMain;
  return gl_test::compile_compute_program(text, log);
}

glm::dvec3 unit(const glm::dvec3& v) { return glm::normalize(v); }

// A case with every input already float (so both sides see the same numbers).
struct Case {
  float sigma_s, sigma_a, g, h, ground, top, t0, t1;
  glm::vec3 origin, direction, sun;
  float depth0, xi, depth;
  std::string name;
  FogMedium medium() const { return fog_medium(sigma_s, sigma_a, g, h, ground, top); }
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
  const double xis[] = {0.0, 0.3, 0.97};
  size_t k = 0;
  for (double sigma : sigmas)
    for (double h : falloffs)
      for (int top = 0; top < 2; ++top)
        for (const Dir& d : dirs)
          for (const glm::dvec3& s : suns)
            for (const Span& span : spans) {
              Case c;
              c.sigma_s = static_cast<float>(0.8 * sigma);
              c.sigma_a = static_cast<float>(0.2 * sigma);
              c.g = 0.6f;
              c.h = static_cast<float>(h);
              c.ground = 0;
              c.top = top ? 40.0f : static_cast<float>(kInf);
              c.t0 = static_cast<float>(span.t0);
              c.t1 = static_cast<float>(span.t1);
              c.origin = glm::vec3(0.25f, 2.0f, -0.5f);
              c.direction = glm::vec3(d.v);
              c.sun = glm::vec3(s);
              c.depth0 = 0;
              c.xi = static_cast<float>(xis[k++ % 3]);
              c.depth = static_cast<float>(0.7 / std::max(sigma, 1e-30));  // τ = 0.7 from the segment's start
              char name[200];
              std::snprintf(name, sizeof name, "σ_t=%g h=%g top=%s dir=%s sun=(%.3g,%.3g,%.3g) t=[%g,%g]", sigma, h,
                            top ? "40" : "none", d.name, s.x, s.y, s.z, span.t0, span.t1);
              c.name = name;
              cases.push_back(c);
            }
  // An eye above the top looking down into it; a segment after a thick stretch; a ground
  // at 1000 m (the renderer passes heights above the ground; this checks `ground` anyway).
  auto extra = [&](float ss, float sa, float h, float ground, float top, glm::dvec3 o, glm::dvec3 d, glm::dvec3 s,
                   float t0, float t1, float depth0, const char* name) {
    Case c{ss, sa, 0.6f, h, ground, top, t0, t1, glm::vec3(o), glm::vec3(unit(d)), glm::vec3(unit(s)), depth0,
           0.5f, 1.0f, name};
    cases.push_back(c);
  };
  extra(0.04f, 0.01f, 0.2f, 0, 30, {0, 60, 0}, {1, -0.5, 0}, {0.3, 1, 0}, 0, 200, 0, "from above the top");
  extra(0.04f, 0.01f, 0.2f, 0, 30, {0, 1, 0}, {1, 0.01, 0}, {0.3, 1, 0}, 10, 400, 2.5f, "depth_to_t0 = 2.5");
  extra(0.012f, 0.001f, 0.04f, 1000, static_cast<float>(kInf), {3, 1001.7, 16}, {-0.1, 0.2, -1}, {0.05, 0.2, -1},
        0, 60, 0, "ground at 1000 m, a low sun");
  extra(0.014f, 0.001f, 0.04f, 0, static_cast<float>(kInf), {0.3, 1.7, 10}, {0.1, 0.15, -1}, {0.12, 0.22, -1}, 0,
        static_cast<float>(kInf), 0, "the pine stand's sky ray");
  return cases;
}

// E for the sun term (fog_test.cpp's case_sun_depth, in double from the C++ closed forms).
double sun_depth(const Case& c) {
  const FogMedium m = c.medium();
  const glm::dvec3 o(c.origin), d(c.direction), s(c.sun);
  const FogClip clip = fog_clip_to_top(m, o, d, c.t0, c.t1);
  if (clip.empty) return c.depth0;
  const double at_start = fog_sun_optical_depth(m, o + clip.t0 * d, s);
  double at_end = kInf;
  if (std::isfinite(clip.t1))
    at_end = fog_optical_depth(m, o, d, clip.t0, clip.t1) + fog_sun_optical_depth(m, o + clip.t1 * d, s);
  return c.depth0 + std::min(at_start, at_end);
}

// The worst error of one quantity (printed for docs/fog.md).
struct Worst {
  double per_depth = 0;
  std::string where;
  void add(double x, double r, double depth, const std::string& name) {
    if (!(std::abs(r) > 1e-25) || !(std::abs(r) < 1e30) || depth > kFloatMaxDepth) return;
    const double p = std::abs(x - r) / std::abs(r) / (1 + depth);
    if (p > per_depth) per_depth = p, where = name;
  }
  void print(const char* what) const {
    std::printf("[ fog twin ] %-18s max |x − r|/(|r|(1 + E)) %.2e at %s\n", what, per_depth, where.c_str());
  }
};

// x (float, from the GLSL) against r (double, from the C++), carrying optical depth E.
void expect_twin(double x, double r, double depth, const Case& c, const char* what, Worst* worst) {
  worst->add(x, r, depth, c.name);
  if (std::isinf(r)) {
    EXPECT_TRUE(std::isinf(x) || x >= 1e30) << what << " " << c.name << ": " << x << " vs +inf";
    return;
  }
  EXPECT_FALSE(std::isnan(x)) << what << " " << c.name;
  EXPECT_GE(x, 0.0) << what << " " << c.name;
  if (r >= 1e30) {  // an optical depth beyond float's kFogFar·σ: both mean T = 0
    EXPECT_GT(x, kFloatMaxDepth) << what << " " << c.name << ": " << x << " vs " << r;
    return;
  }
  if (depth > kFloatMaxDepth) {  // the float result is flushed or below e^{−80} of its prefactor
    EXPECT_LE(x, std::max(2 * r, 1e-25)) << what << " " << c.name << ": " << x << " vs " << r;
    return;
  }
  EXPECT_NEAR(x, r, kFloatRelative * (1 + depth) * std::abs(r) + kFloatFloor) << what << " " << c.name;
}

TEST(GlFogTwin, EveryFogFunctionMatchesItsCppTwin) {
  SYLVA_REQUIRE_GL();
  const std::vector<Case> cases = stiff_cases();
  std::vector<glm::vec4> in;
  for (const Case& c : cases)
    in.insert(in.end(), {glm::vec4(c.sigma_s, c.sigma_a, c.g, c.h), glm::vec4(c.ground, c.top, c.t0, c.t1),
                         glm::vec4(c.origin, c.depth0), glm::vec4(c.direction, c.xi), glm::vec4(c.sun, c.depth)});
  // The elementary functions through their limits: exprel and expm1 at 0, across the
  // series' edge (±0.35) and far out; lnrel up to 1; exp_integral from σ → 0 to unbounded.
  std::vector<glm::vec4> scalars;
  for (double x : {0.0, 1e-30, -1e-12, 1e-8, -1e-4, 0.01, -0.2, 0.3499, -0.3501, 0.35, -0.35, 0.4, 0.49, -0.49,
                   0.5, -0.5, 0.51, 0.9, -0.999, -3.0, -30.0, -79.0, -200.0, 0.999999, 2.0, 40.0})
    for (double rate : {0.0, 1e-12, 0.05, 1.0, 1e3})
      for (double length : {0.0, 1e-3, 1.0, 100.0, kInf})
        scalars.push_back(glm::vec4(static_cast<float>(x), static_cast<float>(length), static_cast<float>(rate), 0));

  std::string log;
  const GLuint program = compute_program(&log);
  ASSERT_NE(program, 0u) << log;
  const size_t n = cases.size(), ns = scalars.size();
  GLuint buffers[4];
  glCreateBuffers(4, buffers);
  glNamedBufferStorage(buffers[0], static_cast<GLsizeiptr>(in.size() * sizeof(glm::vec4)), in.data(), 0);
  glNamedBufferStorage(buffers[1], static_cast<GLsizeiptr>(n * kOut * sizeof(glm::vec4)), nullptr, 0);
  glNamedBufferStorage(buffers[2], static_cast<GLsizeiptr>(ns * sizeof(glm::vec4)), scalars.data(), 0);
  glNamedBufferStorage(buffers[3], static_cast<GLsizeiptr>(ns * sizeof(glm::vec4)), nullptr, 0);
  for (GLuint i = 0; i < 4; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, buffers[i]);
  glUseProgram(program);
  glUniform1ui(glGetUniformLocation(program, "u_count"), static_cast<GLuint>(n));
  glUniform1ui(glGetUniformLocation(program, "u_scalar_count"), static_cast<GLuint>(ns));
  glDispatchCompute(static_cast<GLuint>((std::max(n, ns) + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<glm::vec4> out(n * kOut), scalar_out(ns);
  glGetNamedBufferSubData(buffers[1], 0, static_cast<GLsizeiptr>(out.size() * sizeof(glm::vec4)), out.data());
  glGetNamedBufferSubData(buffers[3], 0, static_cast<GLsizeiptr>(ns * sizeof(glm::vec4)), scalar_out.data());
  glUseProgram(0);
  glDeleteBuffers(4, buffers);
  glDeleteProgram(program);
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  static_assert(kIn == 5 && kOut == 4, "kTwinMain's layout");

  // The elementary functions: relative error of a few float ulps (no optical depth).
  for (size_t i = 0; i < ns; ++i) {
    const double x = scalars[i].x, length = scalars[i].y, rate = scalars[i].z;
    const glm::vec4 r = scalar_out[i];
    const std::string what = "x=" + std::to_string(x) + " length=" + std::to_string(length) + " rate=" +
                             std::to_string(rate);
    if (x <= 80) {
      EXPECT_NEAR(r.x, fog_exprel(x), 1e-6 * fog_exprel(x)) << "exprel " << what;
      EXPECT_NEAR(r.w, std::expm1(x), 1e-6 * std::abs(std::expm1(x)) + 1e-45) << "expm1 " << what;
    }
    if (x < 1) {
      EXPECT_NEAR(r.y, fog_lnrel(x), 2e-6 * fog_lnrel(x)) << "lnrel " << what;
    } else {
      EXPECT_TRUE(std::isinf(r.y)) << "lnrel " << what;
    }
    const double e = fog_exp_integral(length, rate);
    if (e >= 1e30) {
      EXPECT_GE(r.z, 1e29) << "exp_integral " << what;
    } else {
      EXPECT_NEAR(r.z, e, 1e-6 * e) << "exp_integral " << what;
    }
  }
  // The cancellation fog.glsl avoids: (1 − e^{−σL})/σ at σ = 1e-12 is 0 or 1e12·ulp in float.
  {
    const auto at = std::find_if(scalars.begin(), scalars.end(),
                                 [](const glm::vec4& s) { return s.y == 1.0f && s.z == 1e-12f; });
    ASSERT_NE(at, scalars.end());
    EXPECT_NEAR(scalar_out[static_cast<size_t>(at - scalars.begin())].z, 1.0, 1e-7);
  }

  Worst depth_w, transmittance_w, sun_w, sky_w, sun_depth_w, sample_w, distance_w;
  size_t lit_cases = 0;
  for (size_t i = 0; i < n; ++i) {
    const Case& c = cases[i];
    const glm::vec4* r = &out[i * kOut];
    const FogMedium m = c.medium();
    const glm::dvec3 o(c.origin), d(c.direction), s(c.sun);
    // Phase: a ratio of two polynomials, a few ulps.
    EXPECT_NEAR(r[0].x, fog_phase_schlick(m.schlick_k, glm::dot(d, s)), 1e-6 * r[0].x) << "phase " << c.name;
    const double tau = fog_optical_depth(m, o, d, c.t0, c.t1);
    expect_twin(r[0].y, tau, 0, c, "optical_depth", &depth_w);
    expect_twin(r[0].z, fog_transmittance(m, o, d, c.t0, c.t1), tau, c, "transmittance", &transmittance_w);
    const double tau_sun = fog_sun_optical_depth(m, o, s);
    expect_twin(r[0].w, tau_sun, 0, c, "sun_optical_depth", &sun_depth_w);
    expect_twin(r[2].w, fog_sun_transmittance(m, o, s), tau_sun, c, "sun_transmittance", &transmittance_w);
    const FogSegment lit = fog_lit_segment(m, o, d, s, c.t0, c.t1, c.depth0);
    const FogSegment shadowed = fog_shadowed_segment(m, o, d, c.t0, c.t1, c.depth0);
    expect_twin(r[1].x, lit.sun, sun_depth(c), c, "lit_segment.sun", &sun_w);
    expect_twin(r[1].y, lit.sky, c.depth0, c, "lit_segment.sky", &sky_w);
    expect_twin(r[1].z, lit.depth, 0, c, "lit_segment.depth", &depth_w);
    expect_twin(r[1].w, shadowed.sky, c.depth0, c, "shadowed.sky", &sky_w);
    if (lit.sun > 1e-25) ++lit_cases;
    const FogClip clip = fog_clip_to_top(m, o, d, c.t0, c.t1);
    EXPECT_EQ(r[2].z != 0, clip.empty) << "clip " << c.name;
    if (!clip.empty) {
      EXPECT_NEAR(r[2].x, clip.t0, 1e-6 * std::abs(clip.t0) + 1e-30) << "clip.t0 " << c.name;
      if (std::isinf(clip.t1)) {
        EXPECT_TRUE(std::isinf(r[2].y)) << "clip.t1 " << c.name;
      } else {
        EXPECT_NEAR(r[2].y, clip.t1, 1e-6 * std::abs(clip.t1)) << "clip.t1 " << c.name;
      }
    }
    // The sampler: the t whose share of the sunlit integral is xi. Compared in the
    // measure it is defined by: the share F(t) of the C++ integral up to the GLSL's t (a t
    // error where the integrand is negligible costs nothing), within 1e-5 plus what 8 float
    // ulps of t are worth where the integrand is steep (a sun 0.05° up makes it e^{300τ}).
    if (!clip.empty && lit.sun > 1e-20) {
      const double whole = fog_lit_segment(m, o, d, s, c.t0, c.t1, 0).sun;
      auto share_at = [&](double t) { return fog_lit_segment(m, o, d, s, c.t0, t, 0).sun / whole; };
      const double t = r[3].x, ulps = 8 * std::abs(t) * 0x1.0p-23;
      const double share = share_at(t);
      const double resolution = share_at(t + ulps) - share_at(std::max<double>(c.t0, t - ulps));
      sample_w.add(share, c.xi, 0, c.name);
      EXPECT_NEAR(share, c.xi, 1e-5 + resolution) << "sample_lit_segment " << c.name << ": t " << t << " vs "
                                                  << fog_sample_lit_segment(m, o, d, s, c.t0, c.t1, c.xi);
    }
    // The inverse of the optical depth, 0.7 in from the segment's start.
    const double start = clip.empty ? c.t0 : clip.t0;
    const double at = fog_distance_at_depth(m, o, d, start, c.depth);
    if (std::isinf(at)) {
      EXPECT_TRUE(std::isinf(r[3].y) || r[3].y >= 1e30) << "distance_at_depth " << c.name;
    } else if (at < 1e30) {
      distance_w.add(r[3].y, at, 0, c.name);
      EXPECT_NEAR(r[3].y, at, 1e-5 * std::abs(at)) << "distance_at_depth " << c.name;
    }
    EXPECT_NEAR(r[3].z, fog_density(m, c.origin.y), 1e-6 * fog_density(m, c.origin.y)) << "density " << c.name;
  }
  depth_w.print("optical depth");
  transmittance_w.print("transmittance");
  sun_depth_w.print("sun depth");
  sun_w.print("sunlit in-scatter");
  sky_w.print("sky in-scatter");
  sample_w.print("sampler");
  distance_w.print("distance at τ");
  std::printf("[ fog twin ] %zu cases, %zu with sunlit in-scatter above 1e-25\n", n, lit_cases);
  EXPECT_GT(lit_cases, n / 4);
}

}  // namespace
}  // namespace sylva
