// view_picture.cpp — see view_picture.h.
#include "app/studio/view_picture.h"

#include <algorithm>
#include <cmath>

#include "core/gl/gl_api.h"
#include "core/util/color.h"

namespace sylva::studio {

std::vector<double> view_key(const Scene& s) {
  const Camera& c = s.camera;
  return {c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fov_y_deg,
          static_cast<double>(s.width), static_cast<double>(s.height), s.sun.direction.x, s.sun.direction.y,
          s.sun.direction.z, s.sun.angular_radius_deg, s.sun.radiance.x, s.sun.radiance.y, s.sun.radiance.z,
          s.sky.x, s.sky.y, s.sky.z, s.ground.height, s.ground.albedo.x, s.ground.albedo.y, s.ground.albedo.z,
          s.fog ? 1.0 : 0.0, s.fog ? s.fog->sigma_s : 0, s.fog ? s.fog->sigma_a : 0, s.fog ? s.fog->g : 0,
          s.fog ? s.fog->height_falloff : 0, s.fog ? s.fog->top : 0, s.fog ? static_cast<double>(s.fog->mode) : 0,
          s.fog ? static_cast<double>(s.fog->steps) : 0};
}

std::vector<uint8_t> srgb8_rgba(const RenderImage& image) {
  std::vector<uint8_t> rgba(static_cast<size_t>(image.width) * image.height * 4);
  for (size_t i = 0; i < rgba.size() && i < image.beauty.size(); ++i) {
    rgba[i] = (i % 4 == 3) ? static_cast<uint8_t>(std::lround(std::clamp(image.beauty[i], 0.0f, 1.0f) * 255.0f))
                           : linear_to_srgb8(image.beauty[i]);
  }
  return rgba;
}

namespace {

GLuint new_texture(uint32_t width, uint32_t height) {
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_RGBA8, static_cast<GLsizei>(width), static_cast<GLsizei>(height));
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return texture;
}

void fill(GLuint texture, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture, 0, 0, 0, static_cast<GLsizei>(width), static_cast<GLsizei>(height), GL_RGBA,
                      GL_UNSIGNED_BYTE, rgba.data());
}

ImTextureID as_id(GLuint texture) { return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(texture)); }

}  // namespace

ImTextureID make_rgba_texture(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  if (width == 0 || height == 0 || rgba.size() != size_t{width} * height * 4) return nullptr;
  const GLuint texture = new_texture(width, height);
  fill(texture, width, height, rgba);
  return as_id(texture);
}

void free_rgba_texture(ImTextureID texture) {
  const GLuint name = static_cast<GLuint>(reinterpret_cast<intptr_t>(texture));
  if (name) glDeleteTextures(1, &name);
}

ViewTexture::~ViewTexture() {
  if (texture_) glDeleteTextures(1, &texture_);
}

void ViewTexture::upload(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  if (width == 0 || height == 0 || rgba.size() != size_t{width} * height * 4) return;
  if (!texture_ || width_ != width || height_ != height) {
    if (texture_) glDeleteTextures(1, &texture_);
    texture_ = new_texture(width, height);
    width_ = width;
    height_ = height;
  }
  fill(texture_, width, height, rgba);
}

ImTextureID ViewTexture::id() const { return texture_ ? as_id(texture_) : nullptr; }

void PictureViewport::post_plants(const Scene& scene, const RenderOptions& options) {
  ++plants_version_;
  {
    std::lock_guard<std::mutex> lock(mailbox_->mutex);
    mailbox_->plants = PictureMailbox::Plants{scene, options, plants_version_};
    interrupt(true);
  }
  mailbox_->wake.notify_all();
}

std::optional<ViewPicture> PictureViewport::take_finished() {
  std::lock_guard<std::mutex> lock(mailbox_->mutex);
  std::optional<ViewPicture> p = std::move(mailbox_->picture);
  mailbox_->picture.reset();
  stats_.error = mailbox_->error;
  stats_.frusta = mailbox_->frusta;
  stats_.upload_ms = mailbox_->upload_ms;
  stats_.previews = mailbox_->previews;
  return p;
}

ViewImage PictureViewport::image(const Scene& scene) {
  if (std::optional<ViewPicture> p = take_finished()) {
    texture_.upload(p->width, p->height, p->rgba);
    shown_version_ = p->plants_version;
    stats_.passes = std::move(p->passes);
    stats_.render_ms = p->render_ms;
    stats_.preview = p->preview;
  }
  std::vector<double> key = view_key(scene);
  if (key != asked_view_ || asked_version_ != plants_version_) {
    {
      std::lock_guard<std::mutex> lock(mailbox_->mutex);
      mailbox_->view = PictureMailbox::View{scene, plants_version_};
      interrupt(false);
    }
    mailbox_->wake.notify_all();
    asked_view_ = std::move(key);
    asked_version_ = plants_version_;
  }
  if (!texture_.id()) return {};
  bool current = shown_version_ == plants_version_;
  {
    // New plants that cannot be drawn (no segments or leaves, an error): nothing newer will come.
    std::lock_guard<std::mutex> lock(mailbox_->mutex);
    if (mailbox_->built_version == plants_version_ && !mailbox_->error.empty() && !mailbox_->working && !mailbox_->view)
      current = true;
  }
  return ViewImage{texture_.id(), flip_v_, texture_.width(), texture_.height(), current};
}

}  // namespace sylva::studio
