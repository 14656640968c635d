// gl_twin_test.cpp — the GLSL functions against the C++ they mirror, on the same inputs:
// unpack_gpu_segment (skin.glsl vs skin.cpp) and intersect_frustum_f (ray_frustum.glsl vs
// ray_frustum.cpp's float twin), run in a compute shader over the elm's frusta and rays
// aimed at them from every side.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <string>
#include <vector>

#include "core/gl/gl_api.h"
#include "core/gl/gl_shaders.h"
#include "core/geometry/ray_frustum.h"
#include "core/geometry/skin.h"
#include "tests/support/gl_checks.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

// One case per invocation: unpack record i, intersect ray i with it, write what came out.
constexpr const char* kTwinMain = R"glsl(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Segments { GpuSegment segments[]; };
layout(std430, binding = 1) readonly buffer Rays { vec4 rays[]; };  // origin, direction
layout(std430, binding = 2) writeonly buffer Results { vec4 results[]; };
uniform uint u_count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  FrustumF f = unpack_gpu_segment(segments[i]);
  RayF ray = RayF(rays[2u * i].xyz, rays[2u * i + 1u].xyz);
  FrustumHitF hit = intersect_frustum_f(ray, f.shape, 0.0, kInfinity);
  results[5u * i + 0u] = vec4(f.shape.base, f.shape.length_m);
  results[5u * i + 1u] = vec4(f.shape.lower_normal, f.shape.lower_offset);
  results[5u * i + 2u] = vec4(f.shape.upper_normal, f.shape.upper_offset);
  results[5u * i + 3u] = vec4(f.shape.axis, f.shape.slope);
  results[5u * i + 4u] = vec4(float(hit.kind), hit.t, hit.y, float(f.shape.caps));
}
)glsl";

GLuint compute_program(std::string* log) {
  const std::string text = "#version 450 core\n#line 1 0\n" + std::string(embedded_shader("ray_frustum.glsl")) +
                           "#line 1 1\n" + std::string(embedded_shader("skin.glsl")) + "#line 1 2\n" + kTwinMain;
  return gl_test::compile_compute_program(text, log);
}

TEST(GlTwin, UnpackAndIntersectMatchTheCppFloatTwin) {
  SYLVA_REQUIRE_GL();
  // The elm's frusta, one world 10^6 m away too, and rays from all around each.
  Scene scene = gl_test::scene_around(test::grow_preset("elm"));
  std::vector<Frustum> frusta = skin_skeleton(place_plant(scene.plants.front())).frusta;
  const size_t elm = frusta.size();
  for (size_t i = 0; i < elm; i += 7) {
    Frustum far = frusta[i];
    const glm::dvec3 offset(1e6, 0, -1e6);
    far.shape.base += offset;
    far.shape.lower.offset += glm::dot(far.shape.lower.normal, offset);
    far.shape.upper.offset += glm::dot(far.shape.upper.normal, offset);
    frusta.push_back(far);
  }
  std::vector<GpuSegment> records;
  std::vector<float> rays;
  std::vector<FrustumHitF> expected;
  std::vector<UnpackedGpuSegment> unpacked;
  std::vector<glm::dvec3> origins;
  uint64_t state = 12345;
  auto uniform = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (const Frustum& f : frusta) {
    const GpuSegment record = pack_gpu_segment(f);
    const UnpackedGpuSegment u = unpack_gpu_segment(record);
    const glm::dvec3 origin(record.origin_hi[0], record.origin_hi[1], record.origin_hi[2]);
    // A target on the frustum's axis or near its surface, the eye 2–10 sizes away.
    const double size = u.shape.length + std::max(u.shape.radius0, u.shape.radius1);
    const glm::dvec3 target = u.shape.base + uniform() * u.shape.length * u.shape.axis +
                              (uniform() - 0.5) * 2.5 * std::max(u.shape.radius0, u.shape.radius1) *
                                  axis_frame(u.shape.axis).e0;
    const double z = 2 * uniform() - 1, phi = 2 * 3.14159265358979 * uniform();
    const glm::dvec3 from(std::sqrt(1 - z * z) * std::cos(phi), z, std::sqrt(1 - z * z) * std::sin(phi));
    const Ray ray{target + (2 + 8 * uniform()) * size * from, target - (target + size * from)};
    const RayF ray_f = to_float_ray(ray, origin);
    records.push_back(record);
    rays.insert(rays.end(), {ray_f.origin.x, ray_f.origin.y, ray_f.origin.z, 0, ray_f.direction.x, ray_f.direction.y,
                             ray_f.direction.z, 0});
    expected.push_back(intersect_frustum_f(ray_f, to_float_shape(u.shape, origin), 0, INFINITY));
    unpacked.push_back(u);
    origins.push_back(origin);
  }

  std::string log;
  const GLuint program = compute_program(&log);
  ASSERT_NE(program, 0u) << log;
  const size_t n = records.size();
  GLuint buffers[3];
  glCreateBuffers(3, buffers);
  glNamedBufferStorage(buffers[0], static_cast<GLsizeiptr>(n * sizeof(GpuSegment)), records.data(), 0);
  glNamedBufferStorage(buffers[1], static_cast<GLsizeiptr>(rays.size() * sizeof(float)), rays.data(), 0);
  glNamedBufferStorage(buffers[2], static_cast<GLsizeiptr>(n * 20 * sizeof(float)), nullptr, GL_DYNAMIC_STORAGE_BIT);
  for (GLuint i = 0; i < 3; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, buffers[i]);
  glUseProgram(program);
  glUniform1ui(glGetUniformLocation(program, "u_count"), static_cast<GLuint>(n));
  glDispatchCompute(static_cast<GLuint>((n + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> results(n * 20);
  glGetNamedBufferSubData(buffers[2], 0, static_cast<GLsizeiptr>(results.size() * sizeof(float)), results.data());
  glUseProgram(0);
  glDeleteBuffers(3, buffers);
  glDeleteProgram(program);
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  size_t hits = 0, kind_mismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* r = &results[i * 20];
    const UnpackedGpuSegment& u = unpacked[i];
    const double size = u.shape.length + std::max(u.shape.radius0, u.shape.radius1);
    // Unpacking: the same shape as skin.cpp's, relative to origin_hi, to float rounding.
    const glm::dvec3 base = u.shape.base - origins[i];
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(r[k], base[k], 1e-6 * size + 1e-7 * std::abs(origins[i][k]) * 0x1.0p-23) << i;
      EXPECT_NEAR(r[4 + k], u.shape.lower.normal[k], 2e-6) << i;
      EXPECT_NEAR(r[8 + k], u.shape.upper.normal[k], 2e-6) << i;
      EXPECT_NEAR(r[12 + k], u.shape.axis[k], 1e-6) << i;
    }
    EXPECT_NEAR(r[3], u.shape.length, 1e-6 * u.shape.length) << i;
    EXPECT_NEAR(r[7], u.shape.lower.offset - glm::dot(u.shape.lower.normal, origins[i]), 1e-5 * size) << i;
    EXPECT_NEAR(r[11], u.shape.upper.offset - glm::dot(u.shape.upper.normal, origins[i]), 1e-5 * size) << i;
    EXPECT_EQ(static_cast<uint32_t>(r[19]), (u.shape.cap_lower ? 1u : 0u) | (u.shape.cap_upper ? 2u : 0u)) << i;
    // Intersection: the same hit, t to float's accuracy.
    const FrustumHitF& e = expected[i];
    if (static_cast<uint32_t>(r[16]) != e.kind) {
      ++kind_mismatches;
      continue;
    }
    if (e.kind == 0) continue;
    ++hits;
    EXPECT_NEAR(r[17], e.t, 1e-5 * std::abs(e.t)) << i;
    // y is read at origin + t·direction: float's error grows with the distance travelled
    // (2–10 sizes here), not with the frustum's size alone — the joints' short dome and arc
    // pieces (docs/joints.md) showed it, 1.7e-6 against 1e-5 of a 0.14 m piece at 0.7 m.
    const double travelled = std::abs(e.t) * size;  // |direction| = size
    EXPECT_NEAR(r[18], e.y, 1e-5 * std::max(size, travelled)) << i;
  }
  std::printf("[ twin ] %zu cases, %zu hits, %zu hit-kind mismatches\n", n, hits, kind_mismatches);
  EXPECT_GT(hits, n / 4);
  // A different kind only where a ray grazes an edge within float rounding.
  EXPECT_LE(kind_mismatches, n / 500);
}

}  // namespace
}  // namespace sylva
