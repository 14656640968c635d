// scene.cpp — the scene model: fog mode names, bounds and framing, the default scene
// around a skeleton, plant extents, animation defaults, material looks, placing a plant.
// Reading and writing `.scene.json`: scene_json.cpp.
#include "core/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/geometry/leaf_mesh.h"
#include "core/scene/materials.h"
#include "core/util/limits.h"

namespace sylva {

const char* fog_mode_name(FogMode mode) {
  switch (mode) {
    case FogMode::automatic: return "auto";
    case FogMode::brute: return "brute";
    case FogMode::medium: return "medium";
    case FogMode::fast: return "fast";
    case FogMode::refined: return "refined";
    case FogMode::reference: return "reference";
    case FogMode::map: return "map";
  }
  return "auto";
}

std::optional<FogMode> fog_mode_from_name(std::string_view name) {
  for (FogMode m : {FogMode::automatic, FogMode::brute, FogMode::medium, FogMode::fast, FogMode::refined,
                    FogMode::reference, FogMode::map})
    if (name == fog_mode_name(m)) return m;
  return std::nullopt;
}

const char* light_sky_name(LightSky sky) {
  switch (sky) {
    case LightSky::sun: return "sun";
    case LightSky::uniform: return "uniform";
    case LightSky::overcast: return "overcast";
    case LightSky::sun_uniform: return "sun+uniform";
    case LightSky::sun_overcast: return "sun+overcast";
  }
  return "sun";
}

std::optional<LightSky> light_sky_from_name(std::string_view name) {
  for (LightSky s : {LightSky::sun, LightSky::uniform, LightSky::overcast, LightSky::sun_uniform, LightSky::sun_overcast})
    if (name == light_sky_name(s)) return s;
  return std::nullopt;
}

std::optional<std::string> camera_problem(const Camera& camera) {
  for (const auto& [key, p] : {std::pair{"eye", camera.eye}, std::pair{"target", camera.target}})
    for (int k = 0; k < 3; ++k)
      if (!(std::abs(p[k]) <= kMaxCoordinateM))
        return std::string(key) + " coordinates must be within ±1e12 m (docs/limits.md)";
  // Eye and target within ±1e12 m: their difference is finite.
  const glm::dvec3 forward = camera.target - camera.eye;
  if (!(glm::length(forward) > 0)) return std::string("eye and target must differ");
  const std::optional<glm::dvec3> up = rescaled_direction(camera.up);
  if (!up) return std::string("up must not be zero");
  if (!(glm::length(glm::cross(glm::normalize(forward), glm::normalize(*up))) > 1e-9))
    return std::string("up must not be parallel to the view direction");
  if (!(camera.fov_y_deg > 0 && camera.fov_y_deg < 180))
    return std::string("fov_y_deg must be between 0 and 180 degrees");
  return std::nullopt;
}

Camera framing_camera(const glm::dvec3& lo, const glm::dvec3& hi, uint32_t width, uint32_t height) {
  Camera c;
  c.fov_y_deg = 35;
  const glm::dvec3 centre = 0.5 * (lo + hi);
  const double deg = std::numbers::pi / 180;
  const double elevation = 12 * deg, azimuth = 35 * deg;
  const glm::dvec3 toward_eye(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                              std::cos(elevation) * std::cos(azimuth));
  const glm::dvec3 right = glm::normalize(glm::cross(-toward_eye, glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = glm::cross(right, -toward_eye);
  // The box's 8 corners fit the field of view with 8% margin: a corner q (relative to
  // the centre) at camera distance d − q·w is inside when |q·right| <= kx·(d − q·w) and
  // |q·up| <= ky·(d − q·w), so d is the largest of q·w + |q·right|/kx, q·w + |q·up|/ky.
  const double aspect = static_cast<double>(width) / std::max<uint32_t>(height, 1);
  const double ky = std::tan(0.5 * c.fov_y_deg * deg) / 1.08, kx = ky * aspect;
  const double size = std::max(glm::length(hi - lo), 1e-3);
  double distance = 0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec3 q = corner - centre;
    const double along = glm::dot(q, toward_eye);
    distance = std::max({distance, along + std::abs(glm::dot(q, right)) / kx,
                         along + std::abs(glm::dot(q, up)) / ky, along + 0.05 * size});
  }
  c.target = centre;
  c.eye = centre + distance * toward_eye;
  c.up = {0, 1, 0};
  return c;
}

Scene default_scene_for(const Skeleton& skeleton, uint32_t width, uint32_t height) {
  Scene s;
  s.width = width;
  s.height = height;
  s.sun.direction = glm::normalize(glm::dvec3(0.5, 1, 0.3));
  s.fog.reset();
  ScenePlant plant;
  plant.skeleton = skeleton;
  s.plants.push_back(std::move(plant));
  SkeletonBounds b = skeleton_bounds(skeleton);
  double lowest = 0;
  for (const Joint& j : skeleton.joints) lowest = std::min(lowest, j.position_m[1]);
  s.ground.height = lowest;
  s.camera = framing_camera(b.lo, b.hi, width, height);
  return s;
}

std::optional<std::string> plant_extent_problem(const Skeleton& skeleton, const glm::dvec3& position, double scale) {
  double reach = 0;  // bounds |x|, |y|, |z| of a joint after the rotation about y
  for (const Joint& j : skeleton.joints)
    reach = std::max({reach, std::abs(j.position_m[0]) + std::abs(j.position_m[2]) + j.radius_m,
                      std::abs(j.position_m[1]) + j.radius_m});
  const double extent =
      std::max({std::abs(position.x), std::abs(position.y), std::abs(position.z)}) + scale * reach;
  if (extent <= kMaxCoordinateM) return std::nullopt;
  char reaches[64];
  std::snprintf(reaches, sizeof reaches, "%g", extent);
  return std::string("the plant reaches ") + reaches +
         " m from the origin once placed and scaled, beyond the limit of 1e12 m (docs/limits.md)";
}

SceneAnimation animation_defaults(AnimationMotion motion) {
  SceneAnimation a;
  a.motion = motion;
  if (motion == AnimationMotion::dance) {
    a.amplitude_deg = 12;
    a.frequency_hz = 1.2;
    a.branch_amplitude_deg = 8;
    a.branch_frequency_hz = 2.5;
  }
  return a;
}

const char* animation_motion_name(AnimationMotion motion) {
  return motion == AnimationMotion::dance ? "dance" : "sway";
}

uint64_t animation_frame_count(const SceneAnimation& a) {
  return std::max<uint64_t>(1, static_cast<uint64_t>(std::ceil(a.duration_s * a.fps - 1e-9)));
}

glm::dvec3 unit_sun_direction(const glm::dvec3& toward_sun) {
  // read_sun normalises what it reads, and read_scene normalises sun.direction once more.
  return glm::normalize(glm::normalize(toward_sun));
}


std::optional<SegmentTexture> segment_texture(const std::map<uint32_t, SceneMaterial>& table, const Bark* bark,
                                              uint32_t material) {
  if (material == 0 && bark && bark->albedo_texture)
    return SegmentTexture{*bark->albedo_texture, bark->u_repeat, bark->v_per_metre, true};
  if (material == 0 && bark && bark->albedo_rgb) return std::nullopt;
  const auto entry = table.find(material);
  if (entry == table.end() || !entry->second.albedo_image || !entry->second.segment_repeat) return std::nullopt;
  const SceneMaterial::Repeat& r = *entry->second.segment_repeat;
  return SegmentTexture{*entry->second.albedo_image, r.u_repeat, r.v_per_metre, false};
}

MaterialLook material_look(const std::map<uint32_t, SceneMaterial>& table, const Bark* bark, uint32_t material) {
  const auto entry = table.find(material);
  const SceneMaterial* m = entry == table.end() ? nullptr : &entry->second;
  const double* fallback = default_material_albedo(material);
  MaterialLook look{{fallback[0], fallback[1], fallback[2]}, m ? m->specular : 1.0};
  if (material == 0 && bark && bark->albedo_rgb) look.albedo = *bark->albedo_rgb;
  else if (m && m->albedo_rgb) look.albedo = *m->albedo_rgb;
  return look;
}

void override_skin(Scene& scene, SkinStyle style) {
  scene.skin = style;
  for (ScenePlant& p : scene.plants) p.skin = style;
  for (SceneScatter& sc : scene.scatter) sc.skin.reset();
}

glm::dvec3 place_point(const ScenePlant& plant, const glm::dvec3& p) {
  const double angle = plant.rotate_y_deg * std::numbers::pi / 180;
  const double c = std::cos(angle), s = std::sin(angle);
  const double x = plant.scale * p.x, y = plant.scale * p.y, z = plant.scale * p.z;
  // R_y: x' = c x + s z, z' = −s x + c z (right-handed, counter-clockwise seen from +Y).
  return {plant.position.x + c * x + s * z, plant.position.y + y, plant.position.z - s * x + c * z};
}

Skeleton place_plant(const ScenePlant& plant) {
  Skeleton sk = *plant.skeleton;
  for (Joint& j : sk.joints) {
    const glm::dvec3 q = place_point(plant, {j.position_m[0], j.position_m[1], j.position_m[2]});
    j.position_m[0] = q.x, j.position_m[1] = q.y, j.position_m[2] = q.z;
    j.radius_m *= plant.scale;
  }
  for (Leaf& leaf : sk.leaves)
    for (auto& v : leaf.vertices_m) {
      const glm::dvec3 q = place_point(plant, {v[0], v[1], v[2]});
      v = {q.x, q.y, q.z};
    }
  return sk;
}

}  // namespace sylva
