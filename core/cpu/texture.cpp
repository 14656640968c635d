// texture.cpp — bark textures through OpenImageIO's TextureSystem (see texture.h).
#include "core/cpu/texture.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <glm/geometric.hpp>
#include <map>
#include <mutex>

#include "core/scene/height_maps.h"
#include "core/util/color.h"

namespace sylva {

namespace {

using OIIO::TextureOpt;
using OIIO::TextureSystem;

bool finite(double v) { return std::isfinite(v); }

}  // namespace

UvFootprint uv_footprint(const SurfaceHit& hit, const Ray& ray_dx, const Ray& ray_dy) {
  UvFootprint none;
  const glm::dvec3& n = hit.geometric_normal;
  // Normal equations of Δp ≈ dp_du·Δu + dp_dv·Δv.
  const double a = glm::dot(hit.dp_du, hit.dp_du), b = glm::dot(hit.dp_du, hit.dp_dv),
               c = glm::dot(hit.dp_dv, hit.dp_dv);
  const double det = a * c - b * b;
  if (!(det > 1e-12 * a * c) || !finite(det)) return none;
  double du[2], dv[2];
  const Ray* rays[2] = {&ray_dx, &ray_dy};
  for (int i = 0; i < 2; ++i) {
    const double denominator = glm::dot(n, rays[i]->direction);
    const double numerator = glm::dot(n, hit.position - rays[i]->origin);
    if (!(std::abs(denominator) > 1e-12 * glm::length(rays[i]->direction))) return none;
    const glm::dvec3 p = rays[i]->origin + (numerator / denominator) * rays[i]->direction;
    const glm::dvec3 delta = p - hit.position;
    const double pu = glm::dot(hit.dp_du, delta), pv = glm::dot(hit.dp_dv, delta);
    du[i] = (c * pu - b * pv) / det;
    dv[i] = (a * pv - b * pu) / det;
    if (!finite(du[i]) || !finite(dv[i])) return none;
  }
  return {du[0], dv[0], du[1], dv[1]};
}

struct SceneTextures::Impl {
  TextureSystem* system = nullptr;
  uint64_t id = 0;  // distinguishes this object in the per-thread cache
  // An albedo texture laid on segments, with its repeats.
  struct Albedo {
    TextureSystem::TextureHandle* handle = nullptr;
    double u_repeat = 1, v_per_metre = 1;
  };
  struct Plant {
    Albedo wood;  // material 0's (segment_texture: the bark's, else the table's)
    TextureSystem::TextureHandle* height = nullptr;
    double u_repeat = 1, v_per_metre = 1, depth_m = 0;  // the bark's (the relief's)
  };
  std::vector<Plant> plants;
  Albedo materials[kMaterialSlots];  // materials 1.. of the table (segment_texture)
  size_t files = 0;

  // The height field of one height texture. The marcher's point lookups (tens per ray)
  // sample the finest level itself — the texels read once (height_maps.h), bilinear and
  // periodic as TextureSystem's MipModeNoMIP + InterpBilinear (HeightTexels, relief.h),
  // in double, ~10× cheaper than a texture() call; the
  // normal's footprint lookups go through TextureSystem::texture (trilinear MIP-mapping).
  class HeightTexture final : public HeightField {
   public:
    HeightTexture(const Impl* impl, TextureSystem::TextureHandle* handle, HeightTexels texels)
        : impl_(impl), handle_(handle), texels_(std::move(texels)) {
      filtered_options_.swrap = TextureOpt::WrapPeriodic;
      filtered_options_.twrap = TextureOpt::WrapPeriodic;
      filtered_options_.mipmode = TextureOpt::MipModeTrilinear;  // isotropic: 8 texel reads
      filtered_options_.interpmode = TextureOpt::InterpBilinear;
    }
    double height(double s, double t) const override { return texels_.at(s, t); }
    double filtered_height(double s, double t, double width_s, double width_t) const override {
      // Periodic: move the coordinates near [0, 1) in double, so float keeps texel precision.
      const float sf = static_cast<float>(s - std::floor(s)), tf = static_cast<float>(t - std::floor(t));
      float value = 0;
      TextureOpt options = filtered_options_;
      impl_->system->texture(handle_, impl_->perthread(), options, sf, tf, static_cast<float>(width_s), 0, 0,
                             static_cast<float>(width_t), 1, &value);
      return value;
    }
    double gradient_step_s() const override { return 1.0 / texels_.width; }
    double gradient_step_t() const override { return 1.0 / texels_.height; }
    size_t bytes() const { return texels_.bytes(); }

   private:
    const Impl* impl_;
    TextureSystem::TextureHandle* handle_;
    HeightTexels texels_;          // finest level, channel 0 (relief.h)
    TextureOpt filtered_options_;  // MIP-mapped over a footprint: the normal's
  };
  std::map<TextureSystem::TextureHandle*, std::unique_ptr<HeightTexture>> height_fields;

  // Perthread records: one per thread that looked anything up, destroyed with this object.
  // A thread's cache holds one object's record: a thread alternating between two live
  // SceneTextures makes a new record at each switch (correct, only wasteful).
  mutable std::mutex perthread_mutex;
  mutable std::vector<TextureSystem::Perthread*> perthreads;
  TextureSystem::Perthread* perthread() const {
    thread_local uint64_t cached_owner = 0;
    thread_local TextureSystem::Perthread* cached = nullptr;
    if (cached_owner == id) return cached;
    std::lock_guard lock(perthread_mutex);
    TextureSystem::Perthread* info = system->create_thread_info();
    perthreads.push_back(info);
    cached_owner = id;
    cached = info;
    return info;
  }

  ~Impl() {
    if (!system) return;
    for (TextureSystem::Perthread* p : perthreads) system->destroy_thread_info(p);
    TextureSystem::destroy(system, /*teardown_imagecache=*/true);  // its private cache too
  }
};

SceneTextures::SceneTextures() : impl_(std::make_unique<Impl>()) {}
SceneTextures::~SceneTextures() = default;

Expected<std::unique_ptr<SceneTextures>> SceneTextures::open(const Scene& scene) {
  static std::atomic<uint64_t> next_id{1};
  std::optional<Diagnostic> error;
  std::unique_ptr<SceneTextures> textures(new SceneTextures());
  Impl& m = *textures->impl_;
  m.id = next_id.fetch_add(1);
  m.system = TextureSystem::create(/*shared=*/false);
  if (!m.system) return file_diagnostic("", "OpenImageIO: cannot create a texture system");
  m.system->attribute("automip", 1);
  m.system->attribute("autotile", 0);
  m.system->attribute("gray_to_rgb", 1);
  std::map<std::string, TextureSystem::TextureHandle*> handles;
  auto handle_of = [&](const std::string& path) -> TextureSystem::TextureHandle* {
    if (auto it = handles.find(path); it != handles.end()) return it->second;
    TextureSystem::TextureHandle* h = m.system->get_texture_handle(OIIO::ustring(path), m.perthread());
    // The file opens lazily: asking for its spec opens it (nullptr if it cannot be read).
    if (!h || !m.system->good(h) || !m.system->imagespec(h, m.perthread(), 0)) {
      std::string reason = m.system->geterror();
      if (reason.empty()) reason = "OpenImageIO cannot read it";
      error = file_diagnostic(path, "cannot open texture '" + path + "': " + reason);
      return nullptr;
    }
    handles[path] = h;
    return h;
  };
  // The texture segment_texture names for `material` on a plant with `bark` (none: a null handle).
  auto albedo_of = [&](const Bark* bark, uint32_t material, Impl::Albedo* out) {
    const std::optional<SegmentTexture> t = segment_texture(scene.materials, bark, material);
    if (!t) return true;
    *out = {handle_of(t->path), t->u_repeat, t->v_per_metre};
    return out->handle != nullptr;
  };
  for (uint32_t k = 1; k < kMaterialSlots; ++k)
    if (!albedo_of(nullptr, k, &m.materials[k])) return std::move(*error);
  m.plants.resize(scene.plants.size());
  for (size_t p = 0; p < scene.plants.size(); ++p) {
    const Bark& bark = scene.plants[p].bark;
    Impl::Plant& plant = m.plants[p];
    plant.u_repeat = bark.u_repeat;
    plant.v_per_metre = bark.v_per_metre;
    plant.depth_m = bark.relief_depth_m;
    if (!albedo_of(&bark, 0, &plant.wood)) return std::move(*error);
    if (bark.height_texture) {
      if (!(plant.height = handle_of(*bark.height_texture))) return std::move(*error);
      if (!m.height_fields.count(plant.height)) {
        // The point lookups' texels as the GS+R displacement reads them (height_maps.h).
        Expected<HeightTexels> texels = read_height_texels(*bark.height_texture);
        if (!texels) return texels.error();
        m.height_fields[plant.height] =
            std::make_unique<Impl::HeightTexture>(&m, plant.height, std::move(*texels));
      }
    }
  }
  m.files = handles.size();
  return textures;
}

bool SceneTextures::has_albedo(uint32_t plant, uint32_t material) const {
  if (material == 0) return plant < impl_->plants.size() && impl_->plants[plant].wood.handle;
  return material < kMaterialSlots && impl_->materials[material].handle;
}

bool SceneTextures::has_height(uint32_t plant) const {
  return plant < impl_->plants.size() && impl_->plants[plant].height;
}

glm::dvec3 SceneTextures::albedo(uint32_t plant, uint32_t material, double u, double v_m,
                                 const UvFootprint& fp) const {
  const Impl::Albedo& p = material == 0 ? impl_->plants[plant].wood : impl_->materials[material];
  const double s = u * p.u_repeat, t = v_m * p.v_per_metre;
  TextureOpt options;
  options.swrap = TextureOpt::WrapPeriodic;
  options.twrap = TextureOpt::WrapPeriodic;
  float encoded[3] = {0, 0, 0};
  impl_->system->texture(p.handle, impl_->perthread(), options, static_cast<float>(s - std::floor(s)),
                         static_cast<float>(t - std::floor(t)), static_cast<float>(fp.du_dx * p.u_repeat),
                         static_cast<float>(fp.dv_dx * p.v_per_metre), static_cast<float>(fp.du_dy * p.u_repeat),
                         static_cast<float>(fp.dv_dy * p.v_per_metre), 3, encoded);
  return {srgb_to_linear(encoded[0]), srgb_to_linear(encoded[1]), srgb_to_linear(encoded[2])};
}

ReliefMap SceneTextures::relief_map(uint32_t plant) const {
  const Impl::Plant& p = impl_->plants[plant];
  ReliefMap map;
  map.field = p.height ? impl_->height_fields.at(p.height).get() : nullptr;
  map.depth_m = p.depth_m;
  map.u_repeat = p.u_repeat;
  map.v_per_metre = p.v_per_metre;
  return map;
}

size_t SceneTextures::file_count() const { return impl_->files; }

HeightFn height_function_for(const SceneTextures& textures, uint32_t plant) {
  if (!textures.has_height(plant)) return {};
  const ReliefMap map = textures.relief_map(plant);
  const HeightField* field = map.field;
  return relief_displacement([field](double s, double t) { return field->height(s, t); }, map.depth_m,
                             map.u_repeat, map.v_per_metre);
}

}  // namespace sylva
