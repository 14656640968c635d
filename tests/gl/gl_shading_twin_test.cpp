// gl_shading_twin_test.cpp — shaders/shading.glsl against core/light/shading.h, function by
// function on the same inputs (rounded to float first, so only the arithmetic differs):
// run in a compute shader over hand-picked cases (those of tests/light/shading_test.cpp)
// and random ones, and the constants the GLSL got from C++ read back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>
#include <limits>
#include <string>
#include <vector>

#include "core/gl/gl_api.h"
#include "core/gl/gl_shaders.h"
#include "core/light/shading.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

// One case per invocation. In: 7 vec4 (albedo + specular, n + visibility, n_g +
// above_ground, l + direction_y, view, sky, sun). Out: 6 vec4 (sky_ambient + sun_cosine,
// surface_brdf with the lobe + blinn_phong, surface_brdf without + ground_distance,
// sun_reflected, surface_radiance, sky_radiance).
constexpr int kIn = 7, kOut = 6;
constexpr const char* kTwinMain = R"glsl(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Cases { vec4 cases[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };
uniform uint u_count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i == 0u) results[6u * u_count] = vec4(kSpecular, kShininess, kPi, 0.0);
  if (i >= u_count) return;
  vec4 c[7];
  for (uint k = 0u; k < 7u; ++k) c[k] = cases[7u * i + k];
  vec3 albedo = c[0].xyz, n = c[1].xyz, n_geometric = c[2].xyz, l = c[3].xyz, view = c[4].xyz;
  vec3 sky = c[5].xyz, sun = c[6].xyz;
  float specular = c[0].w;
  float visibility = c[1].w;
  float cos_sun = sun_cosine(n, n_geometric, l);
  vec3 brdf = surface_brdf(albedo, n, l, view, 1.0);
  results[6u * i + 0u] = vec4(sky_ambient(albedo, n, sky), cos_sun);
  results[6u * i + 1u] = vec4(brdf, blinn_phong(n, l, view));
  results[6u * i + 2u] = vec4(surface_brdf(albedo, n, l, view, 0.0), ground_distance(c[2].w, c[3].w));
  results[6u * i + 3u] = vec4(sun_reflected(brdf, sun, cos_sun, visibility), 0.0);
  results[6u * i + 4u] =
      vec4(surface_radiance(albedo, n, l, view, specular, sky, sun, cos_sun, visibility), 0.0);
  results[6u * i + 5u] = vec4(sky_radiance(sky), 0.0);
}
)glsl";

GLuint compute_program(std::string* log) {
  std::string text = "#version 450 core\n";
  for (const std::string& define : shading_defines()) text += "#define " + define + "\n";
  text += "#line 1 0\n" + std::string(embedded_shader("shading.glsl")) + "#line 1 1\n" + kTwinMain;
  return gl_test::compile_compute_program(text, log);
}

struct Case {
  glm::vec3 albedo, n, n_geometric, l, view, sky, sun;
  float specular = 1;  // the lobe's weight (a material's `specular`, 0 for the ground)
  float visibility = 1, above_ground = 1, direction_y = -1;
};

glm::dvec3 d(const glm::vec3& v) { return glm::dvec3(v); }

// |actual − expected| within `relative` of the expected value's size (at least `floor`).
void expect_close(const glm::vec3& actual, const glm::dvec3& expected, double relative, double floor,
                  const char* what, size_t i) {
  const double size = std::max({std::abs(expected.x), std::abs(expected.y), std::abs(expected.z), floor});
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(actual[k], expected[k], relative * size) << what << " case " << i;
}

TEST(GlShadingTwin, TheConstantsComeFromCpp) {
  // shading.glsl has no numbers of its own: C++ writes them.
  const std::vector<std::string> defines = shading_defines();
  ASSERT_EQ(defines.size(), 2u);
  EXPECT_EQ(defines[0], "SHADING_SPECULAR 0.04");
  EXPECT_EQ(defines[1], "SHADING_SHININESS 40.0");
  const std::string glsl(embedded_shader("shading.glsl"));
  EXPECT_NE(glsl.find("const float kSpecular = SHADING_SPECULAR;"), std::string::npos);
  EXPECT_NE(glsl.find("const float kShininess = SHADING_SHININESS;"), std::string::npos);
  // The shade pass compiles this file with these defines.
  const ShaderProgramSource shade = shade_program(true);
  EXPECT_NE(std::find(shade.fragment.files.begin(), shade.fragment.files.end(), "shading.glsl"),
            shade.fragment.files.end());
  for (const std::string& define : defines)
    EXPECT_NE(std::find(shade.fragment.defines.begin(), shade.fragment.defines.end(), define),
              shade.fragment.defines.end())
        << define;
  EXPECT_EQ(glsl_float(0.25), "0.25");
  EXPECT_EQ(glsl_float(8), "8.0");
  EXPECT_EQ(glsl_float(1e-30), "1e-30");
}

TEST(GlShadingTwin, EveryShadingFunctionMatchesItsCppTwin) {
  SYLVA_REQUIRE_GL();
  std::vector<Case> cases;
  // The hand-worked cases of shading_test.cpp: a sunlit ground point, a head-on frustum
  // lit at 36.87°, the specular peak, a shadowed point, a grazing sun, a sun below the
  // horizon.
  const glm::vec3 wood(0.30f, 0.20f, 0.12f), ground(0.35f, 0.3f, 0.25f), sky(0.25f, 0.3f, 0.4f), sun(3, 3, 2.8f);
  const glm::vec3 up(0, 1, 0), z(0, 0, 1);
  cases.push_back({ground, up, up, {0.6f, 0.8f, 0}, up, sky, sun, false, 1, 10, -1});
  cases.push_back({wood, z, z, {0.6f, 0, 0.8f}, z, sky, sun, true, 1, 2, -0.5f});
  cases.push_back({wood, z, z, z, z, sky, sun, true, 1, 0, -1});
  cases.push_back({wood, z, z, {0.6f, 0, 0.8f}, z, sky, sun, true, 0, -1, -1});
  cases.push_back({ground, up, up, {std::sqrt(1 - 1e-4f), 0.01f, 0}, up, sky, sun, false, 1, 2, 0});
  cases.push_back({ground, up, up, {0.6f, -0.8f, 0}, up, sky, sun, false, 1, 2, 0.3f});
  // Random ones: normals anywhere, the geometric normal near the shading normal (flipped
  // now and then), views in front, any sun, visibility 0, 1 or between.
  uint64_t state = 2024;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  auto direction = [&] {
    const double zz = 2 * uniform() - 1, phi = 2 * kPi * uniform();
    return glm::dvec3(std::sqrt(1 - zz * zz) * std::cos(phi), zz, std::sqrt(1 - zz * zz) * std::sin(phi));
  };
  for (int i = 0; i < 4000; ++i) {
    Case c;
    const glm::dvec3 n = direction();
    glm::dvec3 ng = glm::normalize(n + 0.3 * direction());
    if (uniform() < 0.1) ng = -ng;
    glm::dvec3 view = direction();
    if (glm::dot(view, n) < 0) view = -view;
    c.albedo = glm::vec3(uniform(), uniform(), uniform());
    c.n = glm::vec3(n);
    c.n_geometric = glm::vec3(ng);
    c.l = glm::vec3(direction());
    c.view = glm::vec3(view);
    c.sky = glm::vec3(uniform(), uniform(), uniform());
    c.sun = glm::vec3(10 * uniform(), 10 * uniform(), 10 * uniform());
    const double w = uniform();
    c.specular = static_cast<float>(w < 0.3 ? 0.0 : w < 0.7 ? 1.0 : uniform());
    const double v = uniform();
    c.visibility = static_cast<float>(v < 0.2 ? 0.0 : v < 0.6 ? 1.0 : uniform());
    c.above_ground = static_cast<float>(20 * uniform() - 2);
    c.direction_y = static_cast<float>(2 * uniform() - 1);
    cases.push_back(c);
  }
  std::vector<glm::vec4> in;
  for (const Case& c : cases)
    in.insert(in.end(), {glm::vec4(c.albedo, c.specular), glm::vec4(c.n, c.visibility),
                         glm::vec4(c.n_geometric, c.above_ground), glm::vec4(c.l, c.direction_y),
                         glm::vec4(c.view, 0), glm::vec4(c.sky, 0), glm::vec4(c.sun, 0)});

  std::string log;
  const GLuint program = compute_program(&log);
  ASSERT_NE(program, 0u) << log;
  const size_t n = cases.size();
  GLuint buffers[2];
  glCreateBuffers(2, buffers);
  glNamedBufferStorage(buffers[0], static_cast<GLsizeiptr>(in.size() * sizeof(glm::vec4)), in.data(), 0);
  glNamedBufferStorage(buffers[1], static_cast<GLsizeiptr>((n * kOut + 1) * sizeof(glm::vec4)), nullptr,
                       GL_DYNAMIC_STORAGE_BIT);
  for (GLuint i = 0; i < 2; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, buffers[i]);
  glUseProgram(program);
  glUniform1ui(glGetUniformLocation(program, "u_count"), static_cast<GLuint>(n));
  glDispatchCompute(static_cast<GLuint>((n + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<glm::vec4> out(n * kOut + 1);
  glGetNamedBufferSubData(buffers[1], 0, static_cast<GLsizeiptr>(out.size() * sizeof(glm::vec4)), out.data());
  glUseProgram(0);
  glDeleteBuffers(2, buffers);
  glDeleteProgram(program);
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  static_assert(kIn == 7 && kOut == 6, "kTwinMain's layout");

  // The constants as the GLSL compiled them: C++'s, rounded to float.
  EXPECT_EQ(out[n * kOut].x, static_cast<float>(shading::kSpecular));
  EXPECT_EQ(out[n * kOut].y, static_cast<float>(shading::kShininess));
  EXPECT_EQ(out[n * kOut].z, static_cast<float>(kPi));

  const double peak = shading::kSpecular * (shading::kShininess + 8) / (8 * kPi);
  size_t near_terminator = 0, lit = 0;
  for (size_t i = 0; i < n; ++i) {
    const Case& c = cases[i];
    const glm::vec4* r = &out[i * kOut];
    // Float rounding: a few ulp on products and sums; the lobe's 40th power multiplies
    // the relative error of n·h by 40.
    expect_close(r[0], shading::sky_ambient(d(c.albedo), d(c.n), d(c.sky)), 1e-6, 0, "sky_ambient", i);
    const double blinn_phong = shading::blinn_phong(d(c.n), d(c.l), d(c.view));
    EXPECT_NEAR(r[1].w, blinn_phong, 2e-5 * blinn_phong + 1e-6 * peak) << "blinn_phong case " << i;
    const glm::dvec3 brdf = shading::surface_brdf(d(c.albedo), d(c.n), d(c.l), d(c.view), true);
    expect_close(r[1], brdf, 2e-5, 0, "surface_brdf (specular)", i);
    expect_close(r[2], shading::surface_brdf(d(c.albedo), d(c.n), d(c.l), d(c.view), false), 1e-6, 0,
                 "surface_brdf (diffuse)", i);
    const double t = shading::ground_distance(c.above_ground, c.direction_y);
    if (std::isinf(t))
      EXPECT_TRUE(std::isinf(r[2].w) && r[2].w > 0) << "ground_distance case " << i << ": " << r[2].w;
    else
      EXPECT_NEAR(r[2].w, t, 1e-6 * t) << "ground_distance case " << i;
    expect_close(r[5], shading::sky_radiance(d(c.sky)), 0, 0, "sky_radiance", i);
    // Within float rounding of the terminator (n·l or n_g·l ≈ 0) float and double may
    // decide differently whether the sun reaches the point: compared elsewhere only.
    const double n_dot_l = glm::dot(d(c.n), d(c.l)), ng_dot_l = glm::dot(d(c.n_geometric), d(c.l));
    if (std::abs(n_dot_l) < 1e-5 || std::abs(ng_dot_l) < 1e-5) {
      ++near_terminator;
      continue;
    }
    const double cos_sun = shading::sun_cosine(d(c.n), d(c.n_geometric), d(c.l));
    EXPECT_NEAR(r[0].w, cos_sun, 1e-6) << "sun_cosine case " << i;
    expect_close(r[3], shading::sun_reflected(brdf, d(c.sun), cos_sun, c.visibility), 2e-5, 0, "sun_reflected", i);
    const glm::dvec3 radiance = shading::surface_radiance(d(c.albedo), d(c.n), d(c.l), d(c.view), c.specular,
                                                          d(c.sky), d(c.sun), cos_sun, c.visibility);
    expect_close(r[4], radiance, 2e-5, 0, "surface_radiance", i);
    if (cos_sun > 0 && c.visibility > 0) ++lit;
  }
  std::printf("[ twin ] %zu cases, %zu lit, %zu near the terminator\n", n, lit, near_terminator);
  EXPECT_GT(lit, n / 5);
  EXPECT_LT(near_terminator, n / 100);
}

}  // namespace
}  // namespace sylva
