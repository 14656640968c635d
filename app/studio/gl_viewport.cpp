// gl_viewport.cpp — see gl_viewport.h.
#include "app/studio/gl_viewport.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"
#include "core/gl/render_gl.h"
#include "core/render_output.h"
#include "core/util/color.h"

namespace sylva::studio {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Everything image() depends on besides the plants.
std::vector<double> view_key(const Scene& s) {
  const Camera& c = s.camera;
  return {c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg,
          static_cast<double>(s.width), static_cast<double>(s.height), s.sun.direction.x, s.sun.direction.y,
          s.sun.direction.z, s.sun.angular_radius_deg, s.sun.radiance.x, s.sun.radiance.y, s.sun.radiance.z,
          s.sky.x, s.sky.y, s.sky.z, s.ground.height, s.ground.albedo.x, s.ground.albedo.y, s.ground.albedo.z};
}

}  // namespace

GlViewport::GlViewport(std::string renderer_name) { stats_.renderer = std::move(renderer_name); }

GlViewport::~GlViewport() {
  renderer_.reset();
  if (texture_) glDeleteTextures(1, &texture_);
}

void GlViewport::set_plants(const Scene& scene, const RenderOptions& options) {
  const auto start = Clock::now();
  renderer_.reset();
  stats_.error.clear();
  options_ = options;
  bool any = false;
  for (const ScenePlant& p : scene.plants) any |= p.skeleton && p.skeleton->segment_count() > 0;
  if (!any) {
    stats_.error = "the plant has no segments";
    fresh_plants_ = true;
    return;
  }
  if (auto why = gl_unsupported(scene, options)) {
    stats_.error = *why;
    return;
  }
  try {
    renderer_ = std::make_unique<GlRenderer>(scene, options);
    stats_.frusta = renderer_->frusta();
  } catch (const std::exception& e) {
    stats_.error = e.what();
  }
  stats_.upload_ms = ms_since(start);
  fresh_plants_ = true;
}

bool GlViewport::present(const Scene& scene) {
  RenderResult result;
  try {
    result = renderer_->render(scene);
  } catch (const std::exception& e) {
    stats_.error = e.what();
    return false;
  }
  const uint32_t w = result.image.width, h = result.image.height;
  std::vector<uint8_t> rgba(static_cast<size_t>(w) * h * 4);
  const std::vector<float>& src = result.image.beauty;
  for (size_t i = 0; i < rgba.size(); ++i)
    rgba[i] = (i % 4 == 3) ? 255 : static_cast<uint8_t>(std::lround(std::clamp(linear_to_srgb(src[i]), 0.0f, 1.0f) * 255));
  if (!texture_ || texture_w_ != w || texture_h_ != h) {
    if (texture_) glDeleteTextures(1, &texture_);
    glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
    glTextureStorage2D(texture_, 1, GL_RGBA8, static_cast<GLsizei>(w), static_cast<GLsizei>(h));
    glTextureParameteri(texture_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(texture_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(texture_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    texture_w_ = w;
    texture_h_ = h;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture_, 0, 0, 0, static_cast<GLsizei>(w), static_cast<GLsizei>(h), GL_RGBA, GL_UNSIGNED_BYTE,
                      rgba.data());
  stats_.passes = std::move(result.passes);
  last_image_ = ViewImage{reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture_)), false, w, h};
  return true;
}

ViewImage GlViewport::image(const Scene& scene) {
  if (!renderer_) return {};
  std::vector<double> key = view_key(scene);
  if (!fresh_plants_ && key == last_view_ && last_image_.texture) return last_image_;
  const auto start = Clock::now();
  if (!present(scene)) return {};
  stats_.render_ms = ms_since(start);
  last_view_ = std::move(key);
  fresh_plants_ = false;
  return last_image_;
}

std::optional<std::string> GlViewport::write_image(const Scene& scene, const RenderOptions& options,
                                                   const std::string& path) {
  try {
    // The viewport's renderer when it was built with these options; else one for this image.
    std::unique_ptr<GlRenderer> own;
    GlRenderer* r = renderer_.get();
    if (!r || options.skin.knuckle_frusta != options_.skin.knuckle_frusta ||
        options.geometry.relief != options_.geometry.relief || options.spp != options_.spp) {
      own = std::make_unique<GlRenderer>(scene, options);
      r = own.get();
    }
    RenderResult result = r->render(scene);
    last_view_.clear();  // the targets were resized: the next picture renders anew
    ImageWriteResult written = write_render(path, result.image);
    if (written.error) return written.error->format();
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  return std::nullopt;
}

}  // namespace sylva::studio
