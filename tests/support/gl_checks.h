// gl_checks.h — what the GL tests share: one headless context per test binary (a test
// skips, saying why, where none can be made), small scenes whose geometry is known, and
// the comparison of a GL render with the CPU reference (render_cpu.h), which writes the
// two images and their difference to the test's temporary folder when it fails.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/gl/gl_context.h"
#include "core/gl/gl_frame_stats.h"
#include "core/light/shadow_cones.h"
#include "core/light/sun_map.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "tests/support/requirements.h"

namespace sylva::gl_test {

// The process's context, made on first use; null when none can be made (then *why says why).
GlContext* shared_context(std::string* why);

// Skips the current test unless a GL 4.5 core context is current (fails instead under
// SYLVA_REQUIRE_GL=1: requirements.h).
#define SYLVA_REQUIRE_GL()                                                             \
  do {                                                                                 \
    std::string why_no_gl;                                                             \
    if (!::sylva::gl_test::shared_context(&why_no_gl))                                  \
      SYLVA_SKIP_WITHOUT_GL(why_no_gl);                                                \
  } while (0)

// A compute program from the whole GLSL `text` (the GlTwin tests: shader files under test
// plus a main that runs them case by case); 0 when it does not compile or link, with the
// compiler's log in *log either way.
unsigned compile_compute_program(const std::string& text, std::string* log);

// The CPU reference's render of `scene` (core/cpu/render_cpu.h render_cpu): what the GL
// images are compared with.
RenderResult cpu_render(const Scene& scene, const RenderOptions& options = {});

// `scene` rendered with the GL backend as the CLI renders it: render_gl with the CPU's sun
// photons and shadow cones for a fog in a cone mode (app/front/render.h render_gl_scene).
RenderResult gl_render(const Scene& scene, const RenderOptions& options = {}, GlFrameStats* stats = nullptr);

// The CPU's shadow cones of `scene`'s plants (skinned in the world) and sun for fog mode
// `mode` from `photons` sun photons (core/cpu/photons.h build_sun_cones).
std::shared_ptr<const ConeSet> cpu_cones(const Scene& scene, FogMode mode, uint64_t photons);

// Fog mode map's sun maps of `scene`'s plants and sun as the CLI builds them (app/front/render.h
// sun_maps_for: the scene fog's resolution and directions).
std::shared_ptr<const std::vector<SunDepthMap>> cpu_sun_maps(const Scene& scene);

// A scene around `skeleton`: 256×192 unless given, the default scene's camera and sun.
Scene scene_around(const Skeleton& skeleton, uint32_t width = 256, uint32_t height = 192);

// One root chain through `joints`.
Skeleton chain_of(std::vector<Joint> joints);

// How a GL render agrees with the CPU's.
struct Agreement {
  double hit_miss = 0;          // fraction of pixels where both hit a plant or both miss
  double depth_median_rel = 0;  // median |Z_gl − Z_cpu| / Z_cpu over pixels both hit
  double depth_max_rel = 0;
  double beauty_mad = 0;        // mean |gl − cpu| over pixels and RGB, linear values
  double beauty_mad_srgb = 0;   // the same on sRGB-encoded values in [0, 1] (what a PNG holds)
  uint64_t hit_pixels = 0;      // pixels the CPU sees a plant in
  uint64_t nan_pixels = 0;      // GL beauty or depth values that are NaN
  std::string describe() const;
};
Agreement compare(const RenderImage& gl, const RenderImage& cpu);

// Renders `scene` on both backends with `options`, prints and records the agreement as
// `name`, and adds a failure (writing the images, write_diff_images) unless it is within
// the GL backend's tolerances (render_gl_test.cpp): hit/miss >= 99.5 %, median relative depth error <= 1e-4, sRGB
// beauty MAD <= 1/255, no NaN, some plant seen. The GL result goes to *gl when given.
Agreement expect_matches_cpu(const std::string& name, const Scene& scene, const RenderOptions& options,
                             RenderResult* gl = nullptr);

// Writes cpu.png, gl.png and diff.png (|gl − cpu| × 8) into a folder named after `name`
// in the test temporary folder; returns the folder.
std::string write_diff_images(const std::string& name, const RenderImage& gl, const RenderImage& cpu);

}  // namespace sylva::gl_test
