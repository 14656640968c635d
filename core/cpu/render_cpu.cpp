// render_cpu.cpp — the CPU reference ray caster (see render_cpu.h for the shading model).
#include "core/cpu/render_cpu.h"
#include "core/geometry/crotch_mesh.h"
#include "core/geometry/plant_mesh.h"

#include "core/scene/culling.h"
#include "core/light/fog.h"
#include "core/scene/fog_integrator.h"
#include "core/cpu/frustum_tracer.h"
#include "core/cpu/instance_tracer.h"
#include "core/scene/instances.h"
#include "core/scene/leaf_images.h"
#include "core/cpu/crotch_tracer.h"
#include "core/cpu/leaf_tracer.h"
#include "core/cpu/mesh_accel.h"
#include "core/cpu/photons.h"
#include "core/cpu/sun_maps.h"
#include "core/scene/render_common.h"
#include "core/light/shading.h"
#include "core/cpu/texture.h"
#include "core/util/math.h"
#include "core/util/parallel.h"
#include "core/util/clock.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace sylva {

FogMode cpu_fog_mode(FogMode mode) { return mode == FogMode::automatic ? FogMode::map : mode; }

namespace {

using render_common::CameraFrame;
using Rng = render_common::SampleRng;
constexpr uint32_t kTile = 32;
constexpr double kInf = std::numeric_limits<double>::infinity();

using render_common::camera_frame;
using render_common::frame_ray;

// A unit direction toward the sun: its centre for a point sun, else uniform over the disc
// (uniform in solid angle: cos θ uniform in [cos α, 1]).
glm::dvec3 sun_sample(const Sun& sun, const glm::dvec3& sun_direction, double cos_alpha, const AxisFrame& frame, Rng& rng) {
  if (sun.angular_radius_deg <= 0) return sun_direction;
  return render_common::sample_sun_disc(sun_direction, cos_alpha, frame, rng);
}

// What one primary sample saw (the trace pass's output, the shade pass's input).
struct PrimaryHit {
  Ray ray;
  SurfaceHit surface;        // plant hit (surface.hit() false: none)
  double ground_t = kInf;    // ground hit; kInf: none
  uint64_t rng_state = 0;
};

// What a tile's work cost, summed over its samples (thread time).
struct TileCost {
  double trace_s = 0, shade_s = 0, fog_s = 0;
  uint64_t shadow_rays = 0;      // the surfaces' shadow rays
  uint64_t fog_rays = 0;         // camera rays integrated through the fog
  uint64_t fog_shadow_rays = 0;  // the fog's shadow rays
  uint64_t fog_map_texels = 0;   // sun-map texels its walks tested (mode map)
  uint64_t fog_stopped = 0;      // fog rays whose sunlit part stopped at kFogNegligibleDepth
};

// The fog's random numbers come from their own stream of the sample (so the surface's
// draws are those of a render without fog).
constexpr uint64_t kFogStream = 0xF06;

class Renderer {
 public:
  Renderer(const Scene& scene, const SceneGeometry& geometry, const RenderOptions& options,
           const SceneTextures* textures, const FogIntegrator* fog)
      : scene_(scene), options_(options), frame_(camera_frame(scene)),
        tracer_(*geometry.tracer), sun_direction_(glm::normalize(scene.sun.direction)),
        sun_frame_(axis_frame(sun_direction_)),
        cos_alpha_(std::cos(scene.sun.angular_radius_deg * kPi / 180)),
        sun_on_(scene.sun.radiance.x > 0 || scene.sun.radiance.y > 0 || scene.sun.radiance.z > 0),
        textures_(textures), leaf_images_(geometry.leaf_images.get()), fog_(fog) {
    // Ray differentials: frame_ray is affine in (x, y), so the neighbouring sample's
    // direction is the direction plus a constant; one pixel / sqrt(spp) (texture.h).
    const double step = 1 / std::sqrt(static_cast<double>(std::max(1u, options.spp)));
    direction_dx_ = (step * 2 * frame_.half_width / frame_.width) * frame_.right;
    direction_dy_ = (-step * 2 * frame_.half_height / frame_.height) * frame_.up;
  }

  // Renders tile `index` into `image`; adds what it cost to *cost.
  void render_tile(uint32_t index, RenderImage& image, TileCost* cost) {
    const uint32_t tiles_x = (scene_.width + kTile - 1) / kTile;
    const uint32_t x0 = (index % tiles_x) * kTile, y0 = (index / tiles_x) * kTile;
    const uint32_t x1 = std::min(x0 + kTile, scene_.width), y1 = std::min(y0 + kTile, scene_.height);
    const uint32_t spp = std::max(1u, options_.spp);
    const uint32_t grid_x = static_cast<uint32_t>(std::ceil(std::sqrt(static_cast<double>(spp))));
    const uint32_t grid_y = (spp + grid_x - 1) / grid_x;
    PrimaryHit hits[kTile * kTile];
    glm::dvec3 sum[kTile * kTile];
    FogRayResult centre_fog[kTile * kTile];  // spp = 1: the sample is the pixel's centre
    for (auto& s : sum) s = glm::dvec3(0);
    for (uint32_t sample = 0; sample < spp; ++sample) {
      Clock::time_point start = Clock::now();
      for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
          PrimaryHit& h = hits[(y - y0) * kTile + (x - x0)];
          Rng rng(sample_seed(x, y, sample));
          double sx = 0.5, sy = 0.5;
          if (spp > 1) {
            sx = ((sample % grid_x) + rng.next_double()) / grid_x;
            sy = ((sample / grid_x) + rng.next_double()) / grid_y;
          }
          trace(frame_ray(frame_, x + sx, y + sy), h);
          h.rng_state = rng.state();
        }
      cost->trace_s += seconds_since(start);
      start = Clock::now();
      const double fog_before = cost->fog_s;
      for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
          const uint32_t k = (y - y0) * kTile + (x - x0);
          sum[k] += shade(hits[k], cost, spp == 1 ? &centre_fog[k] : nullptr);
        }
      cost->shade_s += seconds_since(start) - (cost->fog_s - fog_before);
    }
    for (uint32_t y = y0; y < y1; ++y)
      for (uint32_t x = x0; x < x1; ++x) {
        const uint32_t k = (y - y0) * kTile + (x - x0);
        const glm::dvec3 c = sum[k] / static_cast<double>(spp);
        float* px = &image.beauty[(static_cast<size_t>(y) * scene_.width + x) * 4];
        px[0] = static_cast<float>(c.r), px[1] = static_cast<float>(c.g), px[2] = static_cast<float>(c.b);
        px[3] = 1;
        if (options_.aovs) write_aovs(image, x, y, spp == 1 ? &hits[k] : nullptr, spp == 1 ? &centre_fog[k] : nullptr, cost);
      }
  }

 private:
  // Pixel (x, y)'s sample `sample`: its random stream (sample = spp is the fog AOV's
  // extra centre ray when spp > 1).
  uint64_t sample_seed(uint32_t x, uint32_t y, uint32_t sample) const {
    return (static_cast<uint64_t>(y) * scene_.width + x) * 0x100000001B3ull + sample * 0x9E37ull;
  }

  void trace(const Ray& ray, PrimaryHit& h) {
    h.ray = ray;
    h.surface = tracer_.nearest(ray, 0, kInf);
    const double ground_t = shading::ground_distance(ray.origin.y - scene_.ground.height, ray.direction.y);
    h.ground_t = ground_t < h.surface.t ? ground_t : kInf;
  }

  // Sun visibility from `p` (offset along the geometric normal `n_geometric`, by at least
  // `offset_m`).
  double sun_visibility(const glm::dvec3& p, const glm::dvec3& n_geometric, const glm::dvec3& l,
                        uint64_t* shadow_rays, double offset_m) {
    const double scale = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    Ray shadow{p + std::max(1e-7 * scale, offset_m) * n_geometric, l};
    ++*shadow_rays;
    // The ground cannot shadow anything above it; only plants cast shadows.
    return tracer_.any(shadow, 0, kInf) ? 0.0 : 1.0;
  }

  // The shading model (shading.h) at a surface point, its sun visibility from one shadow
  // ray toward a sample of the sun, cast only where the sun faces the point.
  glm::dvec3 lit(const glm::dvec3& albedo, const glm::dvec3& n, const glm::dvec3& n_geometric,
                 const glm::dvec3& p, const glm::dvec3& view, double specular, Rng& rng,
                 uint64_t* shadow_rays, double shadow_offset_m = 0) {
    if (!sun_on_) return shading::sky_ambient(albedo, n, scene_.sky);
    const glm::dvec3 l = sun_sample(scene_.sun, sun_direction_, cos_alpha_, sun_frame_, rng);
    const double cos_sun = shading::sun_cosine(n, n_geometric, l);
    // Through fog the sunlight arrives attenuated by T_sun (docs/spec/fog.md); where none arrives
    // no shadow ray is needed.
    const double sun_transmittance =
        fog_ && cos_sun > 0 ? fog_sun_transmittance(fog_->medium(), p, sun_direction_) : 1.0;
    const double visibility = cos_sun <= 0 || sun_transmittance == 0
                                  ? 0.0
                                  : sun_visibility(p, n_geometric, l, shadow_rays, shadow_offset_m);
    const glm::dvec3 sun_irradiance = fog_ ? scene_.sun.radiance * sun_transmittance : scene_.sun.radiance;
    return shading::surface_radiance(albedo, n, l, view, specular, scene_.sky, sun_irradiance, cos_sun,
                                     visibility);
  }

  // What the sample sees: the surface (or sky) L_end, and through fog T·L_end + in-scatter,
  // the fog's part stored in *fog_out when asked for.
  glm::dvec3 shade(const PrimaryHit& h, TileCost* cost, FogRayResult* fog_out) {
    const glm::dvec3 end = shade_end(h, &cost->shadow_rays);
    if (!fog_) return end;
    const FogRayResult f = integrate_fog(h, cost);
    if (fog_out) *fog_out = f;
    return f.transmittance * end + f.inscatter;
  }

  // The fog along the sample's ray up to what it hit (docs/spec/fog.md: the first surface, or
  // infinity; above the top the fog's closed forms see no fog).
  FogRayResult integrate_fog(const PrimaryHit& h, TileCost* cost) const {
    const Clock::time_point start = Clock::now();
    const double length = glm::length(h.ray.direction);
    const double t_hit = h.ground_t < kInf ? h.ground_t : h.surface.t;  // kInf: nothing hit
    Rng rng(mix_pair(h.rng_state, kFogStream));
    const FogRayResult f = fog_->integrate(h.ray.origin, h.ray.direction / length, t_hit * length, rng);
    ++cost->fog_rays;
    cost->fog_shadow_rays += f.shadow_rays;
    cost->fog_map_texels += f.map_texels;
    cost->fog_stopped += f.terminated_early ? 1 : 0;
    cost->fog_s += seconds_since(start);
    return f;
  }

  // L_end: the shaded ground or plant, or the sky.
  glm::dvec3 shade_end(const PrimaryHit& h, uint64_t* shadow_rays) {
    Rng rng(h.rng_state);
    const glm::dvec3 view = -glm::normalize(h.ray.direction);
    if (h.ground_t < kInf) {
      const glm::dvec3 p = h.ray.origin + h.ground_t * h.ray.direction;
      return lit(scene_.ground.albedo, shading::kGroundNormal, shading::kGroundNormal, p, view, 0.0, rng,
                 shadow_rays);
    }
    const SurfaceHit& s = h.surface;
    if (!s.hit()) return shading::sky_radiance(scene_.sky);
    glm::dvec3 n = s.shading_normal;
    glm::dvec3 ng = s.geometric_normal;
    if (glm::dot(ng, view) < 0) ng = -ng;   // seen from inside: light the side we see
    if (glm::dot(n, view) < 0) n = -n;
    const ScenePlant& plant = scene_.plants[s.plant];
    // A leaf is never bark (docs/materials.md): the table's look of its material, its image
    // where the table names one (leaf_images.h); a segment of such a material its mean.
    const MaterialLook look =
        segment_look(scene_.materials, s.is_leaf() ? nullptr : &plant.bark, s.material, leaf_images_);
    glm::dvec3 albedo = look.albedo;
    if (s.is_leaf()) {
      if (leaf_images_ && leaf_images_->has_albedo(s.material)) albedo = leaf_images_->albedo(s.material, s.u, s.v_m);
      return lit(albedo, n, ng, s.position, view, look.specular, rng, shadow_rays);
    }
    // A texture on the segments: the bark's (wood only), or the table's (scene.h segment_texture).
    const auto footprint = [&] {
      return uv_footprint(s, {h.ray.origin, h.ray.direction + direction_dx_},
                          {h.ray.origin, h.ray.direction + direction_dy_});
    };
    if (textures_ && textures_->has_albedo(s.plant, s.material)) {
      albedo = textures_->albedo(s.plant, s.material, s.u, s.v_m, footprint());
    }
    // A crotch's fillet (crotch_tracer.h): the other group's colour mixed in, sampled with
    // this hit's footprint (the two frusta's texel sizes differ by their radii at most).
    if (s.blend < 1) {
      glm::dvec3 other = segment_look(scene_.materials, &plant.bark, s.material_other, leaf_images_).albedo;
      if (textures_ && textures_->has_albedo(s.plant, s.material_other)) {
        other = textures_->albedo(s.plant, s.material_other, s.u_other, s.v_m_other, footprint());
      }
      albedo = s.blend * albedo + (1 - s.blend) * other;
    }
    // A relief hit's shadow ray starts a pixel footprint above it (render_cpu.h).
    const bool relief = s.material == 0 && textures_ && options_.geometry.relief && textures_->has_height(s.plant) &&
                        plant.bark.relief_depth_m > 0;
    const double shadow_offset_m = relief ? s.t * glm::length(direction_dy_) : 0.0;
    return lit(albedo, n, ng, s.position, view, look.specular, rng, shadow_rays, shadow_offset_m);
  }

  // The AOVs through pixel (x, y)'s centre: `centre_hit` and `centre_fog` are the sample's
  // own when it was the centre (spp = 1), else null and traced here.
  void write_aovs(RenderImage& image, uint32_t x, uint32_t y, const PrimaryHit* centre_hit,
                  const FogRayResult* centre_fog, TileCost* cost) {
    PrimaryHit local;
    if (!centre_hit) {
      Rng rng(sample_seed(x, y, std::max(1u, options_.spp)));
      trace(frame_ray(frame_, x + 0.5, y + 0.5), local);
      local.rng_state = rng.state();
      centre_hit = &local;
    }
    const SurfaceHit& s = centre_hit->surface;
    const size_t pixel = static_cast<size_t>(y) * scene_.width + x;
    const bool hit = s.hit();
    glm::dvec3 n(0);
    if (hit) {
      n = s.shading_normal;
      if (glm::dot(n, centre_hit->ray.direction) > 0) n = -n;
    }
    if (!image.depth.empty())
      image.depth[pixel] = hit ? static_cast<float>(s.t * glm::length(centre_hit->ray.direction))
                               : std::numeric_limits<float>::infinity();
    if (!image.normal.empty())
      for (int k = 0; k < 3; ++k) image.normal[pixel * 3 + k] = static_cast<float>(n[k]);
    if (!image.uv.empty()) {
      image.uv[pixel * 2 + 0] = hit ? static_cast<float>(s.u) : 0.0f;
      image.uv[pixel * 2 + 1] = hit ? static_cast<float>(s.v_m) : 0.0f;
    }
    if (!image.id.empty()) {
      image.id[pixel * 3 + 0] = hit ? static_cast<float>(s.plant) : -1.0f;
      // A leaf: chain kAovLeafChain, segment its index in the plant's leaves (render_cpu.h).
      image.id[pixel * 3 + 1] = !hit ? -1.0f : s.is_leaf() ? kAovLeafChain : static_cast<float>(s.chain);
      image.id[pixel * 3 + 2] = !hit ? -1.0f : static_cast<float>(s.is_leaf() ? s.leaf : s.segment);
    }
    if (!image.fog.empty()) {
      const FogRayResult f = centre_fog ? *centre_fog : integrate_fog(*centre_hit, cost);
      for (int k = 0; k < 3; ++k) image.fog[pixel * 4 + k] = static_cast<float>(f.inscatter[k]);
      image.fog[pixel * 4 + 3] = static_cast<float>(f.transmittance);
    }
  }

  const Scene& scene_;
  const RenderOptions& options_;
  const CameraFrame frame_;
  const SceneTracer& tracer_;
  const glm::dvec3 sun_direction_;
  const AxisFrame sun_frame_;
  const double cos_alpha_;
  const bool sun_on_;
  const SceneTextures* textures_;  // bark albedo textures; nullptr: none
  const LeafImages* leaf_images_;  // the table's leaf images (leaf_images.h); nullptr: none
  const FogIntegrator* fog_;       // the scene's fog; nullptr: none
  glm::dvec3 direction_dx_{0}, direction_dy_{0};  // ray differentials' direction offsets
};

// The relief of the frusta tracer (relief.h): every plant whose bark has a height map and
// a relief depth > 0, when options.relief. Textures come from `textures`, else are opened
// into g.own_textures. Adds the "relief" pass: its plants, or "none" (no marching).
SceneRelief scene_relief(const Scene& scene, const GeometryOptions& options, const SceneTextures* textures,
                         SceneGeometry& g, std::vector<RenderPass>* passes) {
  SceneRelief relief;
  relief.options = options.relief_options;
  const Clock::time_point start = Clock::now();
  std::vector<char> skinned(scene.plants.size(), 0);  // culled plants have no frusta
  for (uint32_t p : g.plant_of_frustum) skinned[p] = 1;
  std::vector<uint32_t> plants;
  for (uint32_t p = 0; p < scene.plants.size(); ++p)
    if (options.relief && skinned[p] && scene.plants[p].bark.height_texture && scene.plants[p].bark.relief_depth_m > 0)
      plants.push_back(p);
  if (!plants.empty() && !textures) {
    Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(scene);
    if (!opened) throw std::runtime_error(opened.error().message);
    g.own_textures = std::move(*opened);
    textures = g.own_textures.get();
  }
  if (!plants.empty()) {
    relief.plants.resize(scene.plants.size());
    for (uint32_t p : plants) relief.plants[p] = textures->relief_map(p);
  }
  if (passes) {
    const ReliefOptions& o = relief.options;
    passes->push_back({"relief", seconds_since(start),
                       plants.empty() ? std::string("none")
                                      : std::to_string(plants.size()) + (plants.size() == 1 ? " plant, " : " plants, ") +
                                            std::to_string(o.linear_steps) +
                                            " linear + " + std::to_string(o.bisection_steps) + " bisection steps, v " +
                                            (o.exact_v ? "exact" : "linear")});
  }
  return relief;
}

}  // namespace

namespace {

// The geometry of the plants p with (*only)[p] set, every plant when `only` is null
// (build_scene_geometry's contract for those plants; the others have no frusta). With
// `only`, the culling pass is left to the caller: *culled_out counts the plants culled.
SceneGeometry build_plants_geometry(const Scene& scene, const SkinOptions& skin, const GeometryOptions& options,
                                    std::vector<RenderPass>* passes, const SceneTextures* textures,
                                    std::shared_ptr<const LeafImages> images, const Progress& progress,
                                    const std::vector<char>* only,
                                    uint32_t* culled_out = nullptr, double* cull_s_out = nullptr,
                                    std::span<const glm::dvec3> fillet_eyes = {},
                                    double fillet_pixels_per_radian = 0) {
  SceneGeometry g;
  g.leaf_images = images;
  const bool mesh = options.kind == GeometryKind::mesh;
  TessellateOptions tessellation;
  tessellation.level = options.mesh_level;
  // Height maps for GS+R: the caller's textures, else opened here for as long as needed.
  bool any_height = false;
  for (const ScenePlant& plant : scene.plants) any_height = any_height || plant.bark.height_texture.has_value();
  std::unique_ptr<SceneTextures> own_textures;
  if (mesh && options.displace && any_height && !textures) {
    Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(scene);
    if (!opened) throw std::runtime_error(opened.error().message);
    own_textures = std::move(*opened);
    textures = own_textures.get();
  }
  const ViewFrustum view = view_frustum(scene);
  // The fillets a view needs (crotch.h crotch_seen): seen from the scene's camera with
  // culling on; from `fillet_eyes` at fillet_pixels_per_radian where the caller gives them
  // (an instanced prototype: the eye in its frame, one per instance).
  const glm::dvec3 camera_eye = scene.camera.eye;
  const bool fillets_by_view = options.cull || !fillet_eyes.empty();
  const std::span<const glm::dvec3> eyes =
      fillet_eyes.empty() ? std::span<const glm::dvec3>(&camera_eye, 1) : fillet_eyes;
  const double view_pixels_per_radian = fillet_eyes.empty() ? pixels_per_radian(scene) : fillet_pixels_per_radian;
  size_t crotches_found = 0;
  double cull_s = 0, skin_s = 0, tessellate_s = 0, displace_s = 0;
  uint32_t culled = 0, displaced = 0;
  TriangleMesh triangles;
  LeafMesh leaves;
  std::vector<Crotch> crotches;
  for (uint32_t p = 0; p < scene.plants.size(); ++p) {
    if (progress.cancelled()) {  // between plants
      g.cancelled = true;
      return g;
    }
    progress.report(static_cast<double>(p) / static_cast<double>(scene.plants.size()), "geometry");
    if (only && !(*only)[p]) continue;
    const ScenePlant& plant = scene.plants[p];
    const SkinOptions plant_skin = skin.styled(plant.skin);
    Clock::time_point start = Clock::now();
    Skeleton placed = place_plant(plant);
    skin_s += seconds_since(start);
    if (options.cull) {
      start = Clock::now();
      // A relief or displacement reaches out to relief_depth_m beyond the frusta.
      const double relief_m = plant.bark.height_texture ? std::max(0.0, plant.bark.relief_depth_m) : 0.0;
      const bool out = plant_is_culled(scene, view, plant_box(placed, plant_skin, relief_m));
      cull_s += seconds_since(start);
      if (out) {
        ++culled;
        continue;
      }
    }
    start = Clock::now();
    const double plant_count = static_cast<double>(scene.plants.size());
    Expected<SkinnedSkeleton> skinned_or =
        skin_skeleton(placed, plant_skin, progress.part(p / plant_count, (p + 1) / plant_count));
    if (!skinned_or) {  // cancelled
      g.cancelled = true;
      return g;
    }
    const SkinnedSkeleton& skinned = *skinned_or;
    append_leaves(leaves, placed, p);
    const uint32_t first_frustum = static_cast<uint32_t>(g.frusta.size());
    // The plant's crotches (a mesh has its fillets' triangles too, below, and its relief
    // fades into them), then the scene's, by scene frustum: in a view (culling on), only
    // those whose fillet spans kFilletMinPixels or more (crotch.h crotch_seen).
    const std::vector<Crotch> plant_crotches =
        plant_skin.blend_crotches ? find_crotches(placed, skinned.frusta) : std::vector<Crotch>{};
    crotches_found += plant_crotches.size();
    const std::vector<Crotch> seen =  // in the plant's frusta
        fillets_by_view ? crotches_seen(plant_crotches, eyes, view_pixels_per_radian) : plant_crotches;
    for (Crotch c : seen) {
      for (uint32_t& i : c.parent_frusta) i += first_frustum;
      for (uint32_t& i : c.lateral_frusta) i += first_frustum;
      crotches.push_back(std::move(c));
    }
    g.frusta.insert(g.frusta.end(), skinned.frusta.begin(), skinned.frusta.end());
    g.plant_of_frustum.insert(g.plant_of_frustum.end(), skinned.frusta.size(), p);
    skin_s += seconds_since(start);
    if (!mesh) continue;
    check_mesh_fits(tessellation_size(skinned.frusta.size(), tessellation), triangles.memory_bytes());
    const HeightFn height = options.displace && textures ? height_function_for(*textures, p) : HeightFn{};
    TriangleMesh part = plant_mesh(skinned, tessellation, height, plant.bark.relief_depth_m,
                                   options.relief_options.max_depth_per_radius, &tessellate_s, &displace_s,
                                   plant_crotches);
    if (plant_skin.blend_crotches) append_mesh(part, crotch_fillets(seen, placed, skinned.frusta), 0);
    if (height) ++displaced;
    start = Clock::now();
    if (triangles.positions.empty()) {  // the first plant's mesh is taken, not copied
      for (uint32_t& f : part.triangle_frustum) f += first_frustum;
      triangles = std::move(part);
    } else {
      append_mesh(triangles, part, first_frustum);
    }
    tessellate_s += seconds_since(start);
  }
  const std::string plants = std::to_string(scene.plants.size());
  if (passes && options.cull && !only)
    passes->push_back({"culling", cull_s, std::to_string(culled) + " of " + plants + " plants culled"});
  if (culled_out) *culled_out = culled;
  if (cull_s_out) *cull_s_out = cull_s;
  if (passes)
    passes->push_back({"skin", skin_s,
                       std::to_string(scene.plants.size() - culled) + " plants, " + std::to_string(g.frusta.size()) +
                           " frusta" +
                           (crotches_found ? ", " + std::to_string(crotches.size()) + " of " +
                                                 std::to_string(crotches_found) + " crotches blended" +
                                                 (crotches.size() < crotches_found
                                                      ? " (the rest under " + std::to_string(int(kFilletMinPixels)) +
                                                            " px)"
                                                      : std::string())
                                           : std::string())});
  if (passes && mesh)
    passes->push_back({"tessellate", tessellate_s,
                       std::to_string(triangles.triangle_count()) + " triangles, GS " +
                           std::to_string(options.mesh_level) + ", " + std::to_string(triangles.memory_bytes() / 1024) +
                           " KiB"});
  if (passes && displaced > 0)
    passes->push_back({"displace", displace_s, std::to_string(displaced) + " plants by their height maps"});
  Clock::time_point start = Clock::now();
  if (!crotches.empty()) g.crotches = std::make_shared<const CrotchBalls>(std::move(crotches), g.frusta);
  switch (options.kind) {
    case GeometryKind::frusta:
      g.tracer = std::make_unique<FrustumTracer>(g.frusta, g.plant_of_frustum,
                                                 scene_relief(scene, options, textures, g, passes), g.crotches);
      break;
    case GeometryKind::mesh:
      g.tracer = std::make_unique<MeshTracer>(std::move(triangles), g.frusta, g.plant_of_frustum, options.mesh_level,
                                              displaced > 0);
      break;
  }
  // Leaves (leaf_tracer.h): their own triangles beside the frusta or mesh; a scene
  // without leaves keeps its tracer as it is.
  if (!leaves.empty()) {
    auto with_leaves = std::make_unique<LeafTracer>(std::move(leaves), std::move(g.tracer), images);
    g.leaves = with_leaves.get();
    g.tracer = std::move(with_leaves);
  }
  if (passes)
    passes->push_back({"accel build", seconds_since(start),
                       g.tracer->describe() + ", " + std::to_string(g.tracer->memory_bytes() / 1024) + " KiB"});
  progress.report(1, "geometry");
  return g;
}

// A prototype's geometry as a tracer that owns it (the tracers hold spans of its frusta).
class OwningTracer final : public SceneTracer {
 public:
  explicit OwningTracer(SceneGeometry geometry) : geometry_(std::move(geometry)) {}
  SurfaceHit nearest(const Ray& ray, double t_min, double t_max) const override {
    return geometry_.tracer->nearest(ray, t_min, t_max);
  }
  bool any(const Ray& ray, double t_min, double t_max) const override { return geometry_.tracer->any(ray, t_min, t_max); }
  Aabb bounds() const override { return geometry_.tracer->bounds(); }
  size_t memory_bytes() const override {
    return geometry_.tracer->memory_bytes() + geometry_.frusta.size() * (sizeof(Frustum) + sizeof(uint32_t));
  }
  std::string describe() const override { return geometry_.tracer->describe(); }

 private:
  SceneGeometry geometry_;
};

// Whether `plant`'s geometry is the same in its own frame wherever it stands
// (build_instanced_geometry's exceptions).
bool instanceable(const ScenePlant& plant, const SkinOptions& skin, const GeometryOptions& options) {
  if (skin.twist_rad_per_m != 0 && plant.scale != 1) return false;
  if (!plant.bark.height_texture) return true;
  return options.kind == GeometryKind::frusta ? !(options.relief && plant.bark.relief_depth_m > 0) : !options.displace;
}

}  // namespace

SceneGeometry build_scene_geometry(const Scene& scene, const SkinOptions& skin, const GeometryOptions& options,
                                   std::vector<RenderPass>* passes, const SceneTextures* textures,
                                   const Progress& progress) {
  return build_plants_geometry(scene, skin, options, passes, textures, scene_leaf_images(scene), progress, nullptr);
}

SceneGeometry build_instanced_geometry(const Scene& scene, const SkinOptions& skin, const GeometryOptions& options,
                                       std::vector<RenderPass>* passes, const SceneTextures* textures,
                                       const Progress& progress) {
  const Clock::time_point start = Clock::now();
  const PlantInstances groups = plant_instances(scene);
  // Plants per prototype among those that may be instanced: a skeleton only one of them
  // has is skinned in the world (an instance of one saves nothing).
  std::vector<uint32_t> users(groups.distinct(), 0);
  std::vector<char> eligible(scene.plants.size(), 0);
  for (uint32_t p = 0; p < scene.plants.size(); ++p)
    if (instanceable(scene.plants[p], skin, options)) eligible[p] = 1, ++users[groups.prototype_of_plant[p]];
  std::vector<char> in_world(scene.plants.size(), 1);
  for (uint32_t p = 0; p < scene.plants.size(); ++p)
    if (eligible[p] && users[groups.prototype_of_plant[p]] >= 2) in_world[p] = 0;
  const bool any_in_world = std::find(in_world.begin(), in_world.end(), 1) != in_world.end();
  const bool any_instanced = std::find(in_world.begin(), in_world.end(), 0) != in_world.end();
  if (!any_instanced) return build_scene_geometry(scene, skin, options, passes, textures, progress);
  const std::shared_ptr<const LeafImages> images = scene_leaf_images(scene);

  // The plants skinned in the world first (their passes as build_scene_geometry's).
  constexpr double kWorldShare = 0.5;
  SceneGeometry g;
  g.leaf_images = images;
  uint32_t culled = 0;
  double cull_s = 0;
  if (any_in_world) {
    g = build_plants_geometry(scene, skin, options, passes, textures, images, progress.part(0, kWorldShare),
                              &in_world, &culled, &cull_s);
    if (g.cancelled) return g;
  }
  const double instance_start = seconds_since(start);
  // Cull each instance by its prototype's plant box taken to the world (a box around the
  // placed plant's box: culling stays conservative).
  const ViewFrustum view = view_frustum(scene);
  std::vector<int64_t> prototype_index(groups.distinct(), -1);  // into `prototypes`
  std::vector<std::unique_ptr<SceneTracer>> prototypes;
  std::vector<TracedInstance> instances;
  std::vector<Aabb> local_box(groups.distinct());
  std::vector<char> boxed(groups.distinct(), 0);
  const uint32_t world_culled = culled;
  uint64_t prototype_frusta = 0;
  std::vector<uint64_t> frusta_of_prototype;
  // With culling on, each prototype keeps the fillets any of its instances needs: the eye
  // in its frame, one per instance (crotch.h crotch_seen_from_any).
  std::vector<std::vector<glm::dvec3>> eyes_of_prototype(groups.distinct());
  if (options.cull)
    for (uint32_t p = 0; p < scene.plants.size(); ++p)
      if (!in_world[p])
        eyes_of_prototype[groups.prototype_of_plant[p]].push_back(
            PlantTransform::of(scene.plants[p]).to_local(scene.camera.eye));
  const double view_pixels_per_radian = pixels_per_radian(scene);
  const Progress instance_progress = progress.part(kWorldShare, 1);
  for (uint32_t p = 0; p < scene.plants.size(); ++p) {
    if (in_world[p]) continue;
    if (progress.cancelled()) {
      g.cancelled = true;
      return g;
    }
    instance_progress.report(static_cast<double>(p) / static_cast<double>(scene.plants.size()), "geometry");
    const uint32_t k = groups.prototype_of_plant[p];
    const ScenePlant& plant = scene.plants[p];
    const PlantTransform transform = PlantTransform::of(plant);
    if (options.cull) {
      const Clock::time_point cull_start = Clock::now();
      if (!boxed[k]) {
        const ScenePlant& prototype = scene.plants[groups.prototypes[k]];
        local_box[k] = plant_box(*prototype.skeleton, skin.styled(prototype.skin)), boxed[k] = 1;
      }
      const bool out = plant_is_culled(scene, view, transform.world_box(local_box[k]));
      cull_s += seconds_since(cull_start);
      if (out) {
        ++culled;
        continue;
      }
    }
    if (prototype_index[k] < 0) {
      // The prototype: the skeleton skinned in its own frame, a scene of that one plant.
      Scene one;
      one.plants.push_back(scene.plants[groups.prototypes[k]]);
      one.plants[0].position = {0, 0, 0};
      one.plants[0].rotate_y_deg = 0;
      one.plants[0].scale = 1;
      // Its geometry is every instance's: no relief or displacement of the first plant with
      // the skeleton (which may be one of those skinned in the world) may reach it.
      one.plants[0].bark = Bark{};
      GeometryOptions local = options;
      local.cull = false;
      SceneGeometry pg = build_plants_geometry(one, skin, local, nullptr, nullptr, images, {}, nullptr, nullptr,
                                               nullptr, eyes_of_prototype[k], view_pixels_per_radian);
      prototype_index[k] = static_cast<int64_t>(prototypes.size());
      frusta_of_prototype.push_back(pg.frusta.size());
      prototype_frusta += pg.frusta.size();
      // The vector's buffer and the leaf tracer move with pg into the tracer unchanged.
      g.prototypes.push_back({std::span<const Frustum>(pg.frusta), pg.leaves, pg.crotches.get()});
      prototypes.push_back(std::make_unique<OwningTracer>(std::move(pg)));
    }
    const uint32_t index = static_cast<uint32_t>(prototype_index[k]);
    instances.push_back({index, p, transform});
    g.instances.push_back(instances.back());
    g.instance_frusta += frusta_of_prototype[index];
    ++g.instanced_plants;
  }
  g.instanced_skeletons = static_cast<uint32_t>(prototypes.size());
  const double instances_s = seconds_since(start) - instance_start;
  const Clock::time_point accel_start = Clock::now();
  // The plants skinned in the world are one more prototype, at the identity.
  if (any_in_world && g.tracer) {  // an empty one is left out (InstanceTracer)
    instances.push_back({static_cast<uint32_t>(prototypes.size()), TracedInstance::kOwnPlant, PlantTransform{}});
    prototypes.push_back(std::move(g.tracer));
  }
  g.world_leaves = g.leaves;
  g.leaves = nullptr;  // the world plants' leaves are inside the instance tracer now
  auto tracer = std::make_unique<InstanceTracer>(std::move(prototypes), std::move(instances));
  if (passes && options.cull)  // the plants skinned in the world and the instances
    passes->push_back({"culling", cull_s,
                       std::to_string(culled) + " of " + std::to_string(scene.plants.size()) + " plants culled"});
  if (passes) {
    passes->push_back({"instances", instances_s,
                       std::to_string(g.instanced_plants) + " plants as instances of " +
                           std::to_string(g.instanced_skeletons) + " skeletons (" + std::to_string(prototype_frusta) +
                           " frusta skinned for " + std::to_string(g.instance_frusta) + "), " +
                           std::to_string(culled - world_culled) + " of them culled"});
    passes->push_back({"instance accel build", seconds_since(accel_start),
                       tracer->describe() + ", " + std::to_string(tracer->memory_bytes() / 1024) + " KiB"});
  }
  g.tracer = std::move(tracer);
  progress.report(1, "geometry");
  return g;
}

RenderResult render_cpu(const Scene& scene, const RenderOptions& options) {
  RenderResult result;
  for (const ScenePlant& plant : scene.plants)
    if (!plant.skeleton) throw std::logic_error("render_cpu: a plant has no skeleton (call grow_scene_plants)");
  // Bark textures and the table's segment images: opened once, for the shading and for
  // the relief or displacement.
  std::unique_ptr<SceneTextures> textures;
  if (std::any_of(scene.plants.begin(), scene.plants.end(),
                  [](const ScenePlant& p) { return p.bark.albedo_texture || p.bark.height_texture; }) ||
      std::any_of(scene.materials.begin(), scene.materials.end(),
                  [&](const auto& entry) { return segment_texture(scene.materials, nullptr, entry.first).has_value(); })) {
    const Clock::time_point start = Clock::now();
    Expected<std::unique_ptr<SceneTextures>> opened = SceneTextures::open(scene);
    if (!opened) throw std::runtime_error(opened.error().message);
    textures = std::move(*opened);
    result.passes.push_back({"textures", seconds_since(start), std::to_string(textures->file_count()) + " files"});
  }
  // The relief's shading normal is filtered over a pixel's footprint (relief.h): the
  // angle between neighbouring samples' rays at the image centre.
  GeometryOptions geometry_options = options.geometry;
  geometry_options.relief_options.pixel_spread_rad =
      2 * std::tan(0.5 * scene.camera.fov_y_deg * kPi / 180) / scene.height /
      std::sqrt(static_cast<double>(std::max(1u, options.spp)));
  // Progress: the geometry a small share, the tiles the rest.
  constexpr double kGeometryShare = 0.05;
  // Instances (build_instanced_geometry): the fog's sun photons trace them too (photons.h).
  const Progress geometry_progress = options.progress.part(0, kGeometryShare);
  SceneGeometry geometry =
      options.geometry.instance
          ? build_instanced_geometry(scene, options.skin, geometry_options, &result.passes, textures.get(),
                                     geometry_progress)
          : build_scene_geometry(scene, options.skin, geometry_options, &result.passes, textures.get(),
                                 geometry_progress);
  if (geometry.cancelled) {
    result.cancelled = true;
    return result;
  }
  const Progress tile_progress = options.progress.part(kGeometryShare, 1);
  result.frusta = geometry.frusta.size() + geometry.instance_frusta;
  result.geometry_bytes = geometry.tracer->memory_bytes();

  RenderImage& image = result.image;
  image.width = scene.width;
  image.height = scene.height;
  const size_t pixels = static_cast<size_t>(scene.width) * scene.height;
  image.beauty.assign(pixels * 4, 0.0f);
  if (options.aovs & kAovDepth) image.depth.assign(pixels, 0.0f);
  if (options.aovs & kAovNormal) image.normal.assign(pixels * 3, 0.0f);
  if (options.aovs & kAovUv) image.uv.assign(pixels * 2, 0.0f);
  if (options.aovs & kAovId) image.id.assign(pixels * 3, 0.0f);
  if ((options.aovs & kAovFog) && scene.fog) image.fog.assign(pixels * 4, 0.0f);

  // The fog (docs/spec/fog.md): only a scene with a `fog` key runs any of it, and only the
  // modes that read shadow cones trace sun photons (unless the caller brought cones).
  std::optional<FogIntegrator> fog;
  std::unique_ptr<const SunCones> sun_cones;
  std::optional<ConeSetFogSource> cone_source;
  std::optional<Expected<SunMaps>> sun_maps;  // mode map, unless the caller brought maps
  const FogConeSource* cones = options.fog.cones;
  if (scene.fog) {
    FogIntegratorOptions fog_options;
    fog_options.mode = cpu_fog_mode(options.fog.mode.value_or(scene.fog->mode));
    fog_options.steps = options.fog.steps.value_or(scene.fog->steps);
    fog_options.maps = options.fog.maps;
    if (!cones && fog_mode_needs_cones(fog_options.mode)) {
      sun_cones = build_sun_cones(
          geometry, scene,
          sun_cone_options_for(fog_options.mode, options.fog.photons.value_or(scene.fog->photons),
                               options.fog.cone_params, options.threads, options.progress.cancel_flag()));
      result.passes.insert(result.passes.end(), sun_cones->passes.begin(), sun_cones->passes.end());
      if (sun_cones->automatic) result.cone_report = sun_cones->automatic->describe();
      if (sun_cones->cancelled) {
        result.cancelled = true;
        return result;
      }
      cone_source.emplace(sun_cones->cones);
      cones = &*cone_source;
    }
    if (fog_options.mode == FogMode::map) {
      cones = nullptr;  // the maps' tiles index the shadow (docs/fog-map.md): every ray walks them whole
      if (fog_options.maps.empty()) {
        sun_maps.emplace(build_sun_maps_of(geometry, scene, sun_map_tile_photons(scene, options),
                                           sun_map_options_for(scene, options), &result.passes));
        if (!*sun_maps) throw SunMapsRefused(sun_maps->error().message);
        if ((*sun_maps)->cancelled) {
          result.cancelled = true;
          return result;
        }
        fog_options.maps = (*sun_maps)->maps;
      }
    }
    fog.emplace(fog_medium_of(scene), fog_sun_of(scene.sun), scene.sky, *geometry.tracer, cones, fog_options);
  }

  const uint32_t tiles_x = (scene.width + kTile - 1) / kTile;
  const uint32_t tiles_y = (scene.height + kTile - 1) / kTile;
  const uint32_t tiles = tiles_x * tiles_y;
  const unsigned threads = std::min<unsigned>(worker_count(options.threads), tiles);

  Renderer renderer(scene, geometry, options, textures.get(), fog ? &*fog : nullptr);
  std::atomic<uint32_t> done_tiles{0};
  // A worker's costs, a cache line of its own: render_tile adds to them for every pixel.
  struct alignas(64) WorkerCost {
    TileCost cost;
  };
  std::vector<WorkerCost> worker_costs(threads);

  const Clock::time_point start = Clock::now();
  parallel_for(tiles, threads, options.progress.cancel_flag(), [&](size_t tile, unsigned worker) {
    renderer.render_tile(static_cast<uint32_t>(tile), image, &worker_costs[worker].cost);
    const uint32_t done = done_tiles.fetch_add(1, std::memory_order_acq_rel) + 1;
    if (done < tiles) tile_progress.report(static_cast<double>(done) / tiles, "render");
  });
  const double wall = seconds_since(start);
  TileCost total;
  for (const WorkerCost& w : worker_costs) {
    total.trace_s += w.cost.trace_s;
    total.shade_s += w.cost.shade_s;
    total.fog_s += w.cost.fog_s;
    total.shadow_rays += w.cost.shadow_rays;
    total.fog_rays += w.cost.fog_rays;
    total.fog_shadow_rays += w.cost.fog_shadow_rays;
    total.fog_map_texels += w.cost.fog_map_texels;
    total.fog_stopped += w.cost.fog_stopped;
  }
  result.cancelled = done_tiles.load() < tiles;
  if (!result.cancelled) tile_progress.report(1, "render");
  result.primary_rays = pixels * std::max(1u, options.spp);
  result.shadow_rays = total.shadow_rays + total.fog_shadow_rays;
  result.passes.push_back({"trace + shade (wall)", wall,
                           std::to_string(threads) + " threads, " + std::to_string(tiles) + " tiles of 32x32"});
  result.passes.push_back({"trace (thread time)", total.trace_s,
                           std::to_string(result.primary_rays) + " primary rays, " +
                               std::to_string(options.spp) + " spp"});
  result.passes.push_back({"shade (thread time)", total.shade_s,
                           std::to_string(total.shadow_rays) + (scene.sun.angular_radius_deg > 0 ? " soft" : " hard") +
                               " shadow rays"});
  if (fog) {
    const FogMode mode = fog->mode();
    const bool cone_mode = mode == FogMode::medium || mode == FogMode::fast || mode == FogMode::refined;
    std::string detail = std::string(fog_mode_name(mode));
    if (options.fog.mode.value_or(scene.fog->mode) == FogMode::automatic) detail += " (auto)";
    detail += ", " + std::to_string(options.fog.steps.value_or(scene.fog->steps)) + " steps";
    if (cone_mode)
      detail += sun_cones ? ", " + std::to_string(sun_cones->cones.size()) + " shadow cones"
                : cones   ? ", the caller's shadow cones"
                          : ", no shadow cones (every ray searched whole)";
    if (mode == FogMode::map)
      detail += ", " + std::to_string(fog->map_count()) + " sun maps, " + std::to_string(total.fog_map_texels) +
                " map texels walked";
    detail += "; " + std::to_string(total.fog_rays) + " rays, " + std::to_string(total.fog_shadow_rays) +
              " shadow rays, " + std::to_string(total.fog_stopped) + " stopped at T < 4e-18";
    result.passes.push_back({"fog (thread time)", total.fog_s, detail});
  }
  return result;
}

}  // namespace sylva
