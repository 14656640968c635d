// impostor.cpp — see impostor.h.
#include "app/front/impostor.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <utility>

#include <glm/geometric.hpp>

#include "core/cpu/render_cpu.h"
#include "core/util/color.h"
#include "core/util/math.h"

namespace sylva {

CardRenderer cpu_card_renderer(std::map<uint32_t, SceneMaterial> materials, uint32_t spp) {
  return [materials = std::move(materials), spp](const GltfPlant& plant, const ImpostorCard& card, uint32_t width,
                                                 uint32_t height) -> Expected<CardImage> {
    Scene scene;
    scene.width = width;
    scene.height = height;
    scene.materials = materials;
    const double distance = 100 * std::max(card.half_height_m, card.half_width_m);
    scene.camera.eye = card.centre_m + distance * card.normal;
    scene.camera.target = card.centre_m;
    scene.camera.up = {0, 1, 0};
    scene.camera.fov_y_deg = 2 * std::atan(card.half_height_m / distance) / kRadPerDeg;
    scene.sun.direction = unit_sun_direction(card.normal + glm::dvec3(0.3, 1, 0.2));
    ScenePlant sp;
    sp.skeleton = plant.skeleton;
    sp.bark = plant.bark;
    sp.skin = plant.skin;
    scene.plants.push_back(std::move(sp));
    // The ground far below: a ray that misses the plant is uncovered whatever it meets.
    scene.ground.height = card.centre_m.y - 1e6;
    RenderOptions options;
    options.spp = spp;
    options.aovs = kAovDepth;
    options.skin = SkinOptions{}.styled(plant.skin);
    RenderResult rendered;
    try {
      rendered = render_cpu(scene, options);
    } catch (const std::exception& e) {
      return file_diagnostic("", "cannot render the impostor card of " + plant.name + ": " + e.what());
    }
    const RenderImage& image = rendered.image;
    CardImage out;
    out.width = width;
    out.height = height;
    out.rgba.assign(size_t{4} * width * height, 0);
    double mean[3] = {0, 0, 0};
    size_t covered = 0;
    for (size_t p = 0; p < size_t{width} * height; ++p) {
      if (!std::isfinite(image.depth[p])) continue;
      ++covered;
      for (size_t k = 0; k < 3; ++k) {
        out.rgba[4 * p + k] = linear_to_srgb8(image.beauty[4 * p + k]);
        mean[k] += out.rgba[4 * p + k];
      }
      out.rgba[4 * p + 3] = 255;
    }
    for (size_t p = 0; covered > 0 && p < size_t{width} * height; ++p)
      if (out.rgba[4 * p + 3] == 0)
        for (size_t k = 0; k < 3; ++k)
          out.rgba[4 * p + k] = static_cast<uint8_t>(std::lround(mean[k] / static_cast<double>(covered)));
    return out;
  };
}

}  // namespace sylva
