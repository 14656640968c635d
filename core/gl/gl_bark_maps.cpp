// gl_bark_maps.cpp — see gl_bark_maps.h.
#include "core/gl/gl_bark_maps.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"

namespace sylva {

bool relief_mapped(const ScenePlant& plant, const RenderOptions& options) {
  return options.geometry.relief && plant.bark.height_texture && plant.bark.relief_depth_m > 0;
}

std::vector<std::string> bark_image_files(const Scene& scene, const RenderOptions& options) {
  std::set<std::string> images;
  for (uint32_t k = 0; k < kMaterialSlots; ++k)
    if (auto t = segment_texture(scene.materials, nullptr, k)) images.insert(t->path);
  for (const ScenePlant& plant : scene.plants) {
    if (plant.bark.albedo_texture) images.insert(*plant.bark.albedo_texture);
    if (options.geometry.kind == GeometryKind::frusta && relief_mapped(plant, options))
      images.insert(*plant.bark.height_texture);
  }
  return {images.begin(), images.end()};
}

GlBarkMaps::GlBarkMaps(const Scene& scene, const RenderOptions& options) {
  std::map<std::string, int> albedo_unit, height_unit;
  std::map<std::string, std::pair<uint32_t, uint32_t>> height_level;  // first texel, index into height_sizes_
  std::vector<gl::PlantBarkRecord> bark;
  auto albedo_unit_of = [&](const std::string& path) {
    if (!albedo_unit.count(path)) albedo_unit[path] = upload(path, false, nullptr);
    albedo_ = true;
    return albedo_unit[path];
  };
  // The table's images on segments (scene.h segment_texture), per material slot.
  gl::MaterialMapsRecord materials[gl::kMaxMaterials];
  static_assert(gl::kMaxMaterials == kMaterialSlots);
  for (uint32_t k = 0; k < kMaterialSlots; ++k) {
    if (const std::optional<SegmentTexture> t = segment_texture(scene.materials, nullptr, k)) {
      materials[k].u_repeat = static_cast<float>(t->u_repeat);
      materials[k].v_per_metre = static_cast<float>(t->v_per_metre);
      materials[k].albedo_unit = albedo_unit_of(t->path);
    }
  }
  for (const ScenePlant& plant : scene.plants) {
    gl::PlantMapsRecord r;
    r.u_repeat = static_cast<float>(plant.bark.u_repeat);
    r.v_per_metre = static_cast<float>(plant.bark.v_per_metre);
    if (plant.bark.albedo_texture) r.albedo_unit = albedo_unit_of(*plant.bark.albedo_texture);
    else if (plant.bark.albedo_rgb) r.albedo_unit = gl::kAlbedoNone;  // its colour, not the table's image
    else r.albedo_unit = gl::kAlbedoFromTable;
    if (relief_mapped(plant, options)) {
      // The shade pass offsets a relief plant's shadow lookups whatever the geometry
      // (render_cpu.cpp); the frusta pass marches it.
      r.relief_depth_m = static_cast<float>(plant.bark.relief_depth_m);
      if (options.geometry.kind == GeometryKind::frusta) {
        const std::string& path = *plant.bark.height_texture;
        if (!height_unit.count(path)) height_unit[path] = upload(path, true, &height_level[path]);
        r.height_unit = height_unit[path];
        r.height_first = height_level[path].first;
        r.height_width = height_sizes_[height_level[path].second].first;
        r.height_height = height_sizes_[height_level[path].second].second;
        relief_ = true;
      }
    }
    plants_.push_back(r);
    gl::PlantBarkRecord b;
    if (plant.bark.albedo_rgb) {
      b.rgb[0] = static_cast<float>(plant.bark.albedo_rgb->x);
      b.rgb[1] = static_cast<float>(plant.bark.albedo_rgb->y);
      b.rgb[2] = static_cast<float>(plant.bark.albedo_rgb->z);
      b.replaces_material0 = 1;
    }
    bark.push_back(b);
  }
  maps_buffer_ = make_gl_buffer(plants_.data(), plants_.size() * sizeof(gl::PlantMapsRecord));
  height_texel_buffer_ = make_gl_buffer(height_texels_.data(), height_texels_.size() * sizeof(float));
  bark_buffer_ = make_gl_buffer(bark.data(), bark.size() * sizeof(gl::PlantBarkRecord));
  material_maps_buffer_ = make_gl_buffer(materials, sizeof materials);
  uploaded_bytes_ += plants_.size() * sizeof(gl::PlantMapsRecord) + height_texels_.size() * sizeof(float) +
                     bark.size() * sizeof(gl::PlantBarkRecord) + sizeof materials;
  check_gl("bark maps");
}

void GlBarkMaps::bind() const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kPlantMapsBinding, maps_buffer_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kHeightTexelsBinding, height_texel_buffer_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kPlantBarkBinding, bark_buffer_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kMaterialMapsBinding, material_maps_buffer_.id());
  for (size_t i = 0; i < textures_.size(); ++i)
    glBindTextureUnit(gl::kBarkTexturesUnit + static_cast<GLuint>(i), textures_[i].id());
}

// Reads `path` and makes its texture; returns its index (unit kBarkTexturesUnit + index).
// A height map's finest level goes to height_texels_ too (*level: its first texel and the
// index of its size in height_sizes_).
int GlBarkMaps::upload(const std::string& path, bool height, std::pair<uint32_t, uint32_t>* level) {
  if (textures_.size() >= gl::kMaxBarkImages)
    throw GlError("the GL backend binds at most " + std::to_string(gl::kMaxBarkImages) + " distinct bark images");
  auto input = OIIO::ImageInput::open(path);
  if (!input) throw GlError("cannot open texture '" + path + "': " + OIIO::geterror());
  const OIIO::ImageSpec spec = input->spec();
  const int w = std::max(1, spec.width), h = std::max(1, spec.height), channels = std::max(1, spec.nchannels);
  const size_t texels = static_cast<size_t>(w) * h;
  const int levels = 1 + static_cast<int>(std::floor(std::log2(std::max(w, h))));
  textures_.push_back(make_gl_texture_2d(height ? GL_R32F : GL_RGBA8, w, h, levels));
  const GLuint texture = textures_.back().id();
  if (height) {
    std::vector<float> values(texels);
    if (!input->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, values.data()))
      throw GlError("cannot read texture '" + path + "': " + input->geterror());
    glTextureSubImage2D(texture, 0, 0, 0, w, h, GL_RED, GL_FLOAT, values.data());
    *level = {static_cast<uint32_t>(height_texels_.size()), static_cast<uint32_t>(height_sizes_.size())};
    height_sizes_.push_back({w, h});
    height_texels_.insert(height_texels_.end(), values.begin(), values.end());
    texture_bytes_ += texels * sizeof(float) * 7 / 3;  // the MIP chain and the texels
    uploaded_bytes_ += texels * sizeof(float);
  } else {
    std::vector<uint8_t> values(texels * channels), rgba(texels * 4, 255);
    if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, values.data()))
      throw GlError("cannot read texture '" + path + "': " + input->geterror());
    for (size_t i = 0; i < texels; ++i)
      for (int k = 0; k < 3; ++k) rgba[i * 4 + k] = values[i * channels + (channels >= 3 ? k : 0)];
    glTextureSubImage2D(texture, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    texture_bytes_ += texels * 4 * 4 / 3;
    uploaded_bytes_ += texels * 4;
  }
  glGenerateTextureMipmap(texture);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_REPEAT);
  // Isotropic trilinear. GL_TEXTURE_MAX_ANISOTROPY 16 was measured on llvmpipe against
  // OpenImageIO's anisotropic lookups: further from the CPU (close-up bark, MAD 1.23/255
  // against 0.86/255) and two orders of magnitude slower.
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  check_gl("bark textures");
  return static_cast<int>(textures_.size()) - 1;
}

}  // namespace sylva
