// gl_bark_maps.h — a scene's bark, and the images its materials table lays on segments
// (scene.h segment_texture), on the GPU (shaders/bark.glsl, the GLSL side of
// core/cpu/texture.h): each distinct image file once, as a texture with its full MIP chain
// bound at unit kBarkTexturesUnit + i for u_bark_textures[i] (albedo GL_RGBA8 holding the
// file's sRGB-encoded values, decoded in the shader after filtering as texture.h does;
// height GL_R32F), the height maps' finest levels as floats (HeightTexels), one
// PlantMapsRecord and one PlantBarkRecord per plant and one MaterialMapsRecord per
// material slot (bindings.h). Images are read with
// OpenImageIO as the CPU's TextureSystem reads them: 8-bit albedo, a gray albedo as gray
// RGB, height channel 0 as float in [0, 1], row 0 at t = 0.
//
// Uploaded once by the constructor; nothing here changes when the camera, the image size
// or the sun does. Preconditions: as gl_objects.h. Failures throw GlError (an unreadable
// image, more than kMaxBarkImages images).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/gl/bindings.h"
#include "core/gl/gl_objects.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva {

// Whether plant `plant` is relief-mapped (render_cpu.cpp's scene_relief, relief.h).
bool relief_mapped(const ScenePlant& plant, const RenderOptions& options);

// The distinct bark image files GlBarkMaps would upload for `scene` with `options`.
std::vector<std::string> bark_image_files(const Scene& scene, const RenderOptions& options);

class GlBarkMaps {
 public:
  GlBarkMaps(const Scene& scene, const RenderOptions& options);

  // Binds the plant records, the height texels and the images (their storage buffers and
  // texture units, bindings.h).
  void bind() const;

  const std::vector<gl::PlantMapsRecord>& plants() const { return plants_; }
  size_t images() const { return textures_.size(); }
  bool relief() const { return relief_; }  // some plant is relief-mapped (frusta geometry)
  bool albedo() const { return albedo_; }  // some segments have an albedo texture
  uint64_t texture_bytes() const { return texture_bytes_; }  // with MIP chains
  uint64_t uploaded_bytes() const { return uploaded_bytes_; }  // texels and records sent

 private:
  int upload(const std::string& path, bool height, std::pair<uint32_t, uint32_t>* level);

  std::vector<gl::PlantMapsRecord> plants_;
  std::vector<GlTexture> textures_;  // unit kBarkTexturesUnit + i
  std::vector<float> height_texels_;
  std::vector<std::pair<int, int>> height_sizes_;
  bool relief_ = false, albedo_ = false;
  uint64_t texture_bytes_ = 0, uploaded_bytes_ = 0;
  GlBuffer maps_buffer_, height_texel_buffer_, bark_buffer_, material_maps_buffer_;
};

}  // namespace sylva
