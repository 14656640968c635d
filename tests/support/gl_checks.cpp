// gl_checks.cpp — see gl_checks.h.
#include "tests/support/gl_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "app/front/render.h"
#include "core/cpu/photons.h"
#include "core/cpu/render_cpu.h"
#include "core/util/color.h"
#include "core/util/image_io.h"
#include "core/gl/gl_api.h"
#include "core/gl/render_gl.h"

namespace sylva::gl_test {

GlContext* shared_context(std::string* why) {
  static GlContextResult made = create_headless_gl_context();
  if (!made.context && why) *why = made.error;
  if (made.context) made.context->make_current();
  return made.context.get();
}

unsigned compile_compute_program(const std::string& text, std::string* log) {
  const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  const char* pointer = text.c_str();
  glShaderSource(shader, 1, &pointer, nullptr);
  glCompileShader(shader);
  char buffer[4096] = {0};
  glGetShaderInfoLog(shader, sizeof buffer, nullptr, buffer);
  *log = buffer;
  const GLuint program = glCreateProgram();
  glAttachShader(program, shader);
  glLinkProgram(program);
  glDeleteShader(shader);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    glDeleteProgram(program);
    return 0;
  }
  return program;
}

RenderResult cpu_render(const Scene& scene, const RenderOptions& options) { return render_cpu(scene, options); }

RenderResult gl_render(const Scene& scene, const RenderOptions& options, GlFrameStats* stats) {
  return render_gl_scene(scene, options, stats);
}

std::shared_ptr<const ConeSet> cpu_cones(const Scene& scene, FogMode mode, uint64_t photons) {
  const SceneGeometry geometry = build_scene_geometry(scene, SkinOptions{});
  std::shared_ptr<const SunCones> cones =
      build_sun_cones(geometry, scene, sun_cone_options_for(mode, photons, std::nullopt, 0, nullptr));
  return std::shared_ptr<const ConeSet>(cones, &cones->cones);
}

std::shared_ptr<const std::vector<SunDepthMap>> cpu_sun_maps(const Scene& scene) {
  SunMaps maps = sun_maps_for(scene, RenderOptions{}, nullptr);
  return std::make_shared<const std::vector<SunDepthMap>>(std::move(maps.maps));
}

Scene scene_around(const Skeleton& skeleton, uint32_t width, uint32_t height) {
  Scene scene = default_scene_for(skeleton, width, height);
  scene.plants.front().skeleton = skeleton;
  return scene;
}

Skeleton chain_of(std::vector<Joint> joints) {
  Skeleton sk;
  sk.joints = std::move(joints);
  sk.chains = {{0, static_cast<uint32_t>(sk.joints.size()), std::nullopt}};
  return sk;
}

std::string Agreement::describe() const {
  char line[320];
  std::snprintf(line, sizeof line,
                "hit/miss agreement %.4f %%, depth rel. error median %.2e (max %.2e), beauty MAD %.5f linear "
                "(%.3f/255 sRGB), %llu CPU hit pixels, %llu NaN",
                100 * hit_miss, depth_median_rel, depth_max_rel, beauty_mad, 255 * beauty_mad_srgb,
                static_cast<unsigned long long>(hit_pixels), static_cast<unsigned long long>(nan_pixels));
  return line;
}

Agreement compare(const RenderImage& gl, const RenderImage& cpu) {
  Agreement a;
  const size_t pixels = static_cast<size_t>(cpu.width) * cpu.height;
  if (gl.width != cpu.width || gl.height != cpu.height || gl.depth.size() != pixels || cpu.depth.size() != pixels) {
    ADD_FAILURE() << "compare: images differ in size or lack depth";
    return a;
  }
  uint64_t agree = 0;
  std::vector<double> rel;
  double sum = 0, sum_srgb = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const bool gl_hit = !std::isinf(gl.depth[p]), cpu_hit = !std::isinf(cpu.depth[p]);
    if (std::isnan(gl.depth[p])) ++a.nan_pixels;
    agree += gl_hit == cpu_hit;
    a.hit_pixels += cpu_hit;
    if (gl_hit && cpu_hit) rel.push_back(std::abs(static_cast<double>(gl.depth[p]) - cpu.depth[p]) / cpu.depth[p]);
    for (int k = 0; k < 3; ++k) {
      const float g = gl.beauty[p * 4 + k], c = cpu.beauty[p * 4 + k];
      if (std::isnan(g)) ++a.nan_pixels;
      sum += std::abs(static_cast<double>(g) - c);
      sum_srgb += std::abs(static_cast<double>(linear_to_srgb(g)) - linear_to_srgb(c));
    }
  }
  a.hit_miss = static_cast<double>(agree) / pixels;
  if (!rel.empty()) {
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    a.depth_median_rel = rel[rel.size() / 2];
    a.depth_max_rel = *std::max_element(rel.begin(), rel.end());
  }
  a.beauty_mad = sum / (3.0 * pixels);
  a.beauty_mad_srgb = sum_srgb / (3.0 * pixels);
  return a;
}

std::string write_diff_images(const std::string& name, const RenderImage& gl, const RenderImage& cpu) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / ("sylva_gl_" + name);
  std::filesystem::create_directories(dir);
  auto png = [&](const std::string& file, const std::vector<float>& rgba) {
    std::vector<float> encoded(static_cast<size_t>(cpu.width) * cpu.height * 3);
    for (size_t p = 0; p * 3 < encoded.size(); ++p)
      for (int k = 0; k < 3; ++k) encoded[p * 3 + k] = linear_to_srgb(rgba[p * 4 + k]);
    (void)write_image_atomically((dir / file).string(), cpu.width, cpu.height, {"R", "G", "B"}, encoded,
                                 {ChannelFormat::uint8}, true);  // a diagnostic picture: best effort
  };
  png("cpu.png", cpu.beauty);
  png("gl.png", gl.beauty);
  std::vector<float> diff(gl.beauty.size());
  for (size_t i = 0; i < diff.size(); ++i) diff[i] = 8 * std::abs(gl.beauty[i] - cpu.beauty[i]);
  // Hit/miss disagreement in pure red, on top.
  for (size_t p = 0; p < gl.depth.size() && p < cpu.depth.size(); ++p)
    if (std::isinf(gl.depth[p]) != std::isinf(cpu.depth[p])) diff[p * 4] = 1, diff[p * 4 + 1] = diff[p * 4 + 2] = 0;
  png("diff.png", diff);
  return dir.string();
}

Agreement expect_matches_cpu(const std::string& name, const Scene& scene, const RenderOptions& options,
                             RenderResult* gl_out) {
  const RenderResult cpu = render_cpu(scene, options);
  RenderResult gl = render_gl(scene, options);
  const Agreement a = compare(gl.image, cpu.image);
  std::printf("[ agreement ] %s %ux%u: %s\n", name.c_str(), scene.width, scene.height, a.describe().c_str());
  ::testing::Test::RecordProperty("agreement", a.describe());
  const bool ok = a.hit_miss >= 0.995 && a.depth_median_rel <= 1e-4 && a.beauty_mad_srgb <= 1.0 / 255 &&
                  a.nan_pixels == 0 && a.hit_pixels > 0;
  if (!ok) ADD_FAILURE() << name << ": " << a.describe() << "\n  images: " << write_diff_images(name, gl.image, cpu.image);
  if (gl_out) *gl_out = std::move(gl);
  return a;
}

}  // namespace sylva::gl_test
