// render_gl.cpp — the OpenGL ray caster (see render_gl.h for the frame and what differs
// from the CPU reference; the shaders are in shaders/, their bindings in bindings.h).
//
// Reading order: GlRenderer's constructor (what is uploaded once), then draw_frame (one
// frame: begin_frame, then per sample shadow_pass / geometry_pass / shade_pass, then
// present_pass), then the stats (end_frame, take_timed_frames) and read_back.
#include "core/gl/render_gl.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/geometric.hpp>
#include <limits>
#include <map>
#include <stdexcept>

#include "core/gl/bindings.h"
#include "core/gl/gl_api.h"
#include "core/gl/gl_bark_maps.h"
#include "core/gl/gl_crotch_fade.h"
#include "core/gl/gl_fog.h"
#include "core/gl/gl_frame_targets.h"
#include "core/gl/gl_mesh.h"
#include "core/scene/leaf_images.h"
#include "core/gl/gl_objects.h"
#include "core/gl/gl_pass_timers.h"
#include "core/gl/gl_program.h"
#include "core/gl/gl_views.h"
#include "core/gl/gl_instances.h"
#include "core/scene/instances.h"
#include "core/geometry/crotch.h"
#include "core/geometry/relief.h"
#include "core/scene/culling.h"
#include "core/scene/render_common.h"
#include "core/util/math.h"
#include "core/util/clock.h"

namespace sylva {

namespace {

using render_common::CameraFrame;
using render_common::camera_frame;
constexpr int kShadowTexelsMin = 1024;
constexpr int kShadowTexelsMax = 8192;
constexpr double kShadowNormalOffsetTexels = 2;  // receiver offset along its normal
constexpr double kShadowDepthBiasTexels = 0.5;   // and along the sun direction

// The orthographic sun view of one shadow pass, in double (sun_view: as the shaders get it).
struct ShadowFrame {
  glm::dvec3 direction{0, 1, 0};  // unit, toward the sun
  glm::dvec3 e0{1, 0, 0}, e1{0, 0, 1};  // axis_frame(direction)
  glm::dvec3 centre{0};           // c
  double x_min = 0, y_min = 0, side = 1;  // square map, metres
  double s_near = 0, s_range = 1;         // s = −dot(p − c, direction)
  double texel_m = 0;
};

// One instanced draw (INSTANCED): a shared skeleton's records, once per plant of it.
struct InstancedDraw {
  uint32_t first_record = 0, records = 0;
  uint32_t first_instance = 0, instances = 0;
};

GlSunView sun_view(const ShadowFrame& f, uint32_t texels) {
  GlSunView v;
  const GlFloatSplit c = split_to_floats(f.centre);
  v.light_hi = c.hi;
  v.light_lo = c.lo;
  v.e0 = glm::vec3(f.e0);
  v.e1 = glm::vec3(f.e1);
  v.direction = glm::vec3(f.direction);
  v.rect = glm::vec4(static_cast<float>(f.x_min), static_cast<float>(f.y_min), static_cast<float>(f.side),
                     static_cast<float>(f.side));
  v.depth = glm::vec2(static_cast<float>(f.s_near), static_cast<float>(f.s_range));
  v.map_size = glm::vec2(static_cast<float>(texels), static_cast<float>(texels));
  return v;
}

using Sphere = GlMeshSphere;  // gl_mesh.h: centre and radius, metres

bool sun_shines(const Scene& scene) {
  return scene.sun.radiance.x > 0 || scene.sun.radiance.y > 0 || scene.sun.radiance.z > 0;
}

// The square orthographic view along `direction` that holds every sphere, `texels` a side.
ShadowFrame shadow_frame(const std::vector<Sphere>& spheres, const glm::dvec3& direction, uint32_t texels) {
  ShadowFrame f;
  f.direction = direction;
  const AxisFrame frame = axis_frame(direction);
  f.e0 = frame.e0;
  f.e1 = frame.e1;
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const Sphere& s : spheres) {
    lo = glm::min(lo, s.centre - s.radius);
    hi = glm::max(hi, s.centre + s.radius);
  }
  f.centre = 0.5 * (lo + hi);
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0, s0 = 0, s1 = 0;
  for (const Sphere& s : spheres) {
    const glm::dvec3 d = s.centre - f.centre;
    const double x = glm::dot(d, f.e0), y = glm::dot(d, f.e1), depth = -glm::dot(d, direction);
    x0 = std::min(x0, x - s.radius), x1 = std::max(x1, x + s.radius);
    y0 = std::min(y0, y - s.radius), y1 = std::max(y1, y + s.radius);
    s0 = std::min(s0, depth - s.radius), s1 = std::max(s1, depth + s.radius);
  }
  // Square texels, two texels of border, the depth range padded by 1 %.
  const double side = std::max({x1 - x0, y1 - y0, 1e-30});
  f.side = side * texels / (texels - 4.0);
  f.x_min = 0.5 * (x0 + x1) - 0.5 * f.side;
  f.y_min = 0.5 * (y0 + y1) - 0.5 * f.side;
  const double pad = 0.01 * std::max(s1 - s0, 1e-30);
  f.s_near = s0 - pad;
  f.s_range = (s1 + pad) - f.s_near;
  f.texel_m = f.side / texels;
  return f;
}

}  // namespace

namespace {

// The fog pass's mode for the mode `options` or the scene ask for (auto: map, the only GL
// mode that reaches below the shadow map's floor — docs/spec/fog.md's "refined's accuracy
// fastest", measured in docs/benchmarks.md), or nullopt where the GPU has none: refined and
// reference (their exact shadow transitions need shadow rays, docs/gl-fog.md).
std::optional<GlFogMode> gl_fog_mode_of(FogMode mode) {
  switch (mode) {
    case FogMode::brute: return GlFogMode::brute;
    case FogMode::medium: return GlFogMode::medium;
    case FogMode::fast: return GlFogMode::fast;
    case FogMode::automatic:
    case FogMode::map: return GlFogMode::map;
    default: return std::nullopt;
  }
}

FogMode requested_fog_mode(const Scene& scene, const RenderOptions& options) {
  return options.fog.mode.value_or(scene.fog->mode);
}

// Why the fog pass cannot draw `scene`'s fog in the mode `options` or the scene ask for,
// or nullopt when it can (or there is no fog).
std::optional<std::string> gl_fog_unsupported(const Scene& scene, const RenderOptions& options) {
  if (!scene.fog) return std::nullopt;
  const FogMode mode = requested_fog_mode(scene, options);
  if (gl_fog_mode_of(mode)) return std::nullopt;
  return std::string("the GL backend's fog pass runs brute, medium, fast and map (auto) only (the fog asks for ") +
         fog_mode_name(mode) + "; --fog-mode brute, medium, fast or map draws it with OpenGL)";
}

}  // namespace

bool gl_fog_walks_maps(FogMode mode) { return gl_fog_mode_of(mode) == GlFogMode::map; }

std::optional<std::string> gl_unsupported(const Scene& scene, const RenderOptions& options) {
  if (auto why = gl_fog_unsupported(scene, options)) return why;
  const size_t images = bark_image_files(scene, options).size();  // what GlBarkMaps uploads
  if (images > gl::kMaxBarkImages)
    return "the GL backend binds at most " + std::to_string(gl::kMaxBarkImages) +
           " distinct bark images (this scene has " + std::to_string(images) + ")";
  return std::nullopt;
}

// ---- Frame: what one draw() records ------------------------------------------------------

struct GlRenderer::Frame {
  Clock::time_point start;
  GlFrameStats stats;
  uint32_t width = 0, height = 0, spp = 1;
  CameraFrame camera;
  double near = 1e-3;               // reversed-Z near plane, metres along forward
  double differential_step = 1;     // 1 / sqrt(spp): the ray differentials' step (texture.h)
  glm::dvec3 ray_dx{0}, ray_dy{0};  // the next sample's direction to the right / below
  bool sun_on = false;
  glm::dvec3 sun_radiance{0};
  bool fog_on = false;     // the scene has fog: shade[FOG] and the fog pass
  GlFogMode fog_mode = GlFogMode::brute;
  bool fog_cones = false;  // a cone mode with cones uploaded: the cone pass runs
  bool fog_maps = false;   // mode map: the sun maps are bound
  uint32_t fog_steps = 0;  // the fog's samples along each ray (brute; medium inside the cones)
  std::vector<uint32_t> eye_inside;  // frusta whose pyramid may reach the eye's near plane
                                     // (instanced: pairs of instance, record)
  uint32_t eye_inside_frusta = 0;    // how many
  GLuint gbuffer_program = 0, inside_program = 0, shadow_program = 0, shade_program = 0, fog_program = 0,
         fog_cones_program = 0, present_program = 0;
  GlCameraView camera_view;  // this sample's (its jitter set per geometry pass)
  ShadowFrame shadow;  // the last shadow pass's view: the shade passes look it up
};

// ---- State: what lives as long as the renderer ------------------------------------------

struct GlRenderer::State {
  RenderOptions options;
  uint32_t shadow_texels_override = 0;  // set_shadow_map_texels; 0: shadow_map_texels()
  std::vector<RenderPass> setup_passes;
  size_t plant_count = 0;
  uint64_t frusta = 0;               // frusta drawn (an instanced skeleton's once per plant)
  uint64_t record_count = 0;         // GpuSegment records uploaded (a shared skeleton's once)
  // Instancing (docs/scatter.md "Instancing"): one draw per shared skeleton, the plants
  // skinned in the world first (the identity instance); empty: one plain draw of every record.
  std::vector<InstancedDraw> draws;
  uint32_t instanced_plants = 0;
  uint64_t uploaded_bytes = 0;       // the geometry: segment records + ids, or the mesh
  uint64_t pending_plant_bytes = 0;  // plant data sent since the last frame
  // Spheres that together hold everything drawn (the near plane, the shadow map's frame):
  // first one around each bounding pyramid of a plant skinned in the world (record i), then
  // one per instanced plant (instance_spheres[j]), then the mesh's or the leaves' (gl_mesh.h).
  std::vector<Sphere> spheres;
  uint32_t world_spheres = 0;
  struct InstanceSphere {
    uint32_t draw = 0, instance = 0;
    PlantTransform transform;
  };
  std::vector<InstanceSphere> instance_spheres;
  // Per draw, its skeleton's pyramids' spheres in the skeleton's frame (the frusta around
  // the eye are looked for among them only inside an instanced plant's sphere).
  std::vector<std::vector<Sphere>> draw_spheres;
  FrustaFeatures features;           // the frusta program's switches for this scene (gl_shaders.h)
  std::optional<GlFogCones> fog_cones;  // set_fog_cones: once per (plants, sun)
  std::optional<GlFogMaps> fog_maps;    // set_fog_maps: once per (plants, sun)
  GlFogLists fog_lists;                 // the cone intervals per pixel (cone modes)
  uint32_t fog_nodes_wanted = 0;        // the most list nodes a cone pass asked for so far
  std::unique_ptr<GlBarkMaps> bark_maps;
  std::unique_ptr<GlMesh> mesh;      // GeometryKind::mesh: the polygon baseline, drawn instead of the frusta
  std::unique_ptr<GlMesh> leaves;    // the plants' leaves (GlMesh::leaves_of), drawn after either; null: none
  std::unique_ptr<GlMesh> fillets;   // the crotches' fillets beside the frusta (GlMesh::fillets_of); null: none
  std::shared_ptr<const LeafImages> leaf_images;  // the table's leaf materials (leaf_images.h); null: none

  GlVertexArray vao;  // empty: the frusta pull their vertices from the records
  GlBuffer segment_buffer, id_buffer, list_buffer, instance_buffer;
  // The blended crotches of the plants with a relief, their frusta as record indices
  // (skin_plants), and their tables on the GPU (CROTCH_FADE, gl_crotch_fade.h).
  std::vector<Crotch> fade_crotches;
  GlBuffer crotch_buffer, crotch_list_buffer;
  // The context's programs (shared with other renderers on it, or this renderer's own) and
  // this renderer's variants in them by name: the cache assembles a variant's sources to
  // find it, done once per variant here rather than per frame.
  std::shared_ptr<GlProgramCache> program_cache;
  std::map<std::string, GLuint> programs;

  GlFrameTargets targets;
  GlShadowMap shadow_map;
  GlPassTimers timers;

  uint64_t frames = 0;
  GlFrameStats last;                      // the last frame drawn
  std::vector<GlFrameStats> in_flight;    // drawn, GPU times not in yet, oldest first
  std::optional<GlFrameStats> newest_timed;  // not yet handed out by timed_frame

  ShaderProgramSource frusta_variant(FrustaPass pass) const { return frusta_program(pass, features); }

  // The program of a variant, built on first use (its compile time added to *compile_s,
  // its name to *compiled).
  GLuint program(const ShaderProgramSource& source, double* compile_s, std::string* compiled = nullptr) {
    auto found = programs.find(source.name);
    if (found != programs.end()) return found->second;
    const GLuint id = program_cache->get(source, compile_s, compiled);
    programs.emplace(source.name, id);
    return id;
  }

  // The view the fillets' relief fade is for (skin_plants sets it; options.geometry.cull).
  glm::dvec3 fillet_eye{0};
  double fillet_pixels_per_radian = 0;

  // Skins one skeleton (placed: in the world) into records and id quadruples (plant, chain,
  // segment, 0), and its frusta's bounding spheres into *out.
  void skin_one(const Skeleton& skeleton, uint32_t plant, SkinStyle style, const Progress& progress,
                std::vector<GpuSegment>* records, std::vector<uint32_t>* ids, std::vector<Sphere>* out,
                std::vector<Crotch>* crotches) const {
    Expected<SkinnedSkeleton> skinned_or = skin_skeleton(skeleton, options.skin.styled(style), progress);
    if (!skinned_or) throw GlCancelled();  // the only error skin_skeleton returns
    const SkinnedSkeleton& skinned = *skinned_or;
    const float plant_relief_m = bark_maps->plants().empty() ? 0.0f : bark_maps->plants()[plant].relief_depth_m;
    if (plant_relief_m > 0 && options.skin.styled(style).blend_crotches) {
      // The relief fades into the fillets (crotch.glsl): the crotches, by record index —
      // with culling on, those whose fillets the view draws (gl_mesh.cpp, crotch.h
      // crotch_seen; the fade of a fillet left out would only flatten the relief).
      const uint32_t first = static_cast<uint32_t>(records->size());
      for (Crotch c : find_crotches(skeleton, skinned.frusta)) {
        if (options.geometry.cull && !crotch_seen(c, fillet_eye, fillet_pixels_per_radian)) continue;
        for (uint32_t& i : c.parent_frusta) i += first;
        for (uint32_t& i : c.lateral_frusta) i += first;
        crotches->push_back(std::move(c));
      }
    }
    for (const Frustum& f : skinned.frusta) {
      records->push_back(pack_gpu_segment(f));
      ids->insert(ids->end(), {plant, f.chain, f.segment, 0u});
      // A relief-mapped segment is drawn in the pyramid of its shell (frusta.vert.glsl).
      const float relief_depth_m = bark_maps->plants().empty() ? 0.0f : bark_maps->plants()[plant].relief_depth_m;
      const BoundingPyramid pyramid =
          bounding_pyramid(relief_depth_m > 0 && f.kind == FrustumKind::segment
                               ? relief_shell(f.shape, relief_depth_m, options.geometry.relief_options.max_depth_per_radius)
                               : f.shape);
      glm::dvec3 centre(0);
      for (const glm::dvec3& v : pyramid.vertices) centre += v / 8.0;
      double radius = 0;
      for (const glm::dvec3& v : pyramid.vertices) radius = std::max(radius, glm::length(v - centre));
      // The shader grows the pyramid by ~1e-4 of the frustum's size (frusta.vert.glsl).
      out->push_back({centre, radius * 1.001 + 1e-3 * (f.shape.length + std::max(f.shape.radius0, f.shape.radius1))});
    }
  }

  // Whether plant p may be drawn through its transform: its geometry is the same in its
  // own frame wherever it stands (no relief, whose depth is in world metres; with a twist,
  // which turns per world metre, scale 1) — build_instanced_geometry's rule on the CPU.
  bool instanceable(const ScenePlant& plant, uint32_t p) const {
    if (options.skin.twist_rad_per_m != 0 && plant.scale != 1) return false;
    return bark_maps->plants().empty() || !(bark_maps->plants()[p].relief_depth_m > 0);
  }

  // Skins every plant of `scene` into records and ids, and replaces `spheres` with the
  // frusta's (one per frustum of a plant in the world, one per instanced plant). With
  // options.geometry.instance, the plants that share a skeleton with another instanceable
  // plant (gl_instances.h) are skinned once per skeleton in its frame and drawn through
  // *instances (draws); the others are skinned in the world, first, under the identity
  // instance. Nothing shared: no instances, one plain draw (as without instancing). Sets
  // frusta and records. Cancelled (options.progress): throws GlCancelled with `spheres` as
  // they were.
  void skin_plants(const Scene& scene, std::vector<GpuSegment>* records, std::vector<uint32_t>* ids,
                   std::vector<GpuInstance>* instances) {
    const uint32_t n = static_cast<uint32_t>(scene.plants.size());
    for (const ScenePlant& plant : scene.plants)
      if (!plant.skeleton) throw std::logic_error("GlRenderer: a plant has no skeleton (call grow_scene_plants)");
    const GlInstanceGroups split = gl_instance_groups(scene, options.geometry.instance,
                                                      [&](uint32_t p) { return instanceable(scene.plants[p], p); });
    std::vector<Sphere> fresh;
    std::vector<InstancedDraw> fresh_draws;
    std::vector<InstanceSphere> fresh_instance_spheres;
    std::vector<std::vector<Sphere>> fresh_draw_spheres;
    std::vector<Crotch> fresh_crotches;
    fillet_eye = scene.camera.eye;
    fillet_pixels_per_radian = pixels_per_radian(scene);
    const double share = 1.0 / std::max(1u, n);
    for (uint32_t p : split.world) {
      if (options.progress.cancelled()) throw GlCancelled();  // between plants
      skin_one(place_plant(scene.plants[p]), p, scene.plants[p].skin, options.progress.part(p * share, (p + 1) * share),
               records, ids, &fresh, &fresh_crotches);
    }
    const uint32_t world_records = static_cast<uint32_t>(records->size());
    uint64_t drawn = world_records;
    instanced_plants = 0;
    if (split.instanced()) {
      // The world plants' records: the identity instance, drawn as they are.
      if (world_records > 0) {
        fresh_draws.push_back({0, world_records, static_cast<uint32_t>(instances->size()), 1});
        fresh_draw_spheres.emplace_back();
        instances->push_back(gpu_instance(PlantTransform{}, 0, true));
      }
      std::vector<Sphere> bounds;  // one per instanced plant, after the world's
      for (const std::vector<uint32_t>& group : split.groups) {
        if (options.progress.cancelled()) throw GlCancelled();
        const uint32_t first = static_cast<uint32_t>(records->size());
        // The first plant drawn through it stands for the skeleton (the skeleton's first
        // plant may be one skinned in the world, with a relief none of these has).
        const uint32_t prototype = group.front();
        std::vector<Sphere> local;
        skin_one(*scene.plants[prototype].skeleton, prototype, scene.plants[prototype].skin, {}, records, ids, &local,
                 &fresh_crotches);
        const Sphere bound = enclosing_sphere(local);
        const uint32_t draw_index = static_cast<uint32_t>(fresh_draws.size());
        InstancedDraw draw{first, static_cast<uint32_t>(records->size()) - first,
                           static_cast<uint32_t>(instances->size()), static_cast<uint32_t>(group.size())};
        for (uint32_t p : group) {
          const PlantTransform t = PlantTransform::of(scene.plants[p]);
          const uint32_t instance = static_cast<uint32_t>(instances->size());
          instances->push_back(gpu_instance(t, p, false));
          bounds.push_back({t.to_world(bound.centre), bound.radius * t.scale * (1 + 1e-6)});
          fresh_instance_spheres.push_back({draw_index, instance, t});
        }
        instanced_plants += draw.instances;
        drawn += uint64_t{draw.records} * draw.instances;
        fresh_draws.push_back(draw);
        fresh_draw_spheres.push_back(std::move(local));
      }
      world_spheres = static_cast<uint32_t>(fresh.size());
      fresh.insert(fresh.end(), bounds.begin(), bounds.end());
    } else {
      world_spheres = static_cast<uint32_t>(fresh.size());
    }
    spheres = std::move(fresh);
    draws = std::move(fresh_draws);
    instance_spheres = std::move(fresh_instance_spheres);
    draw_spheres = std::move(fresh_draw_spheres);
    features.instanced = !draws.empty();
    fade_crotches = std::move(fresh_crotches);
    features.crotch_fade = !fade_crotches.empty();
    frusta = drawn;
    record_count = records->size();
  }

  // Uploads the crotches' fade tables for `records` (none: no buffers); their bytes.
  uint64_t upload_crotch_fade(std::span<const GpuSegment> records) {
    const GlCrotchFadeTables tables = pack_crotch_fade(fade_crotches, records);
    crotch_buffer = tables.empty() ? GlBuffer() : make_gl_buffer(tables.crotches.data(), tables.crotches.size() * sizeof(gl::GpuCrotchRecord));
    crotch_list_buffer = tables.empty() ? GlBuffer() : make_gl_buffer(tables.lists.data(), tables.lists.size() * sizeof(uint32_t));
    return tables.bytes();
  }

  // Draws the frusta's pyramids with `program` (in use): every record once, or (instanced)
  // one instanced draw per shared skeleton, u_instance_base its first instance.
  void draw_frusta(GLuint program) const {
    if (draws.empty()) {
      if (record_count > 0) glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(record_count * gl::kPyramidVertices));
      return;
    }
    for (const InstancedDraw& d : draws) {
      set_uniform_uint(program, "u_instance_base", d.first_instance);
      glDrawArraysInstanced(GL_TRIANGLES, static_cast<GLint>(d.first_record * gl::kPyramidVertices),
                            static_cast<GLsizei>(d.records * gl::kPyramidVertices), static_cast<GLsizei>(d.instances));
    }
  }

  // The shadow map's side for a w × h frame: a texel about a pixel where the plants fill
  // the picture (the default framing); the map's fill dominates a frame on llvmpipe.
  static uint32_t shadow_map_texels(uint32_t w, uint32_t h) {
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    int texels = kShadowTexelsMin;
    while (texels < static_cast<int>(std::max(w, h)) && texels < kShadowTexelsMax) texels *= 2;
    return static_cast<uint32_t>(std::min(texels, max_size));
  }

  // The camera of frame `f`; the reversed-Z near plane far below any hit that matters, far
  // above float's smallest; the frusta around the eye; the ray differentials.
  void frame_views(const Scene& scene, Frame& f) {
    f.camera = camera_frame(scene);
    double farthest = 1e-3;
    for (const Sphere& sphere : spheres)
      farthest = std::max(farthest, glm::length(sphere.centre - f.camera.eye) + sphere.radius);
    f.near = 1e-6 * farthest;
    f.camera_view = camera_view(f.camera, f.near, f.width, f.height);
    // Frusta whose pyramid may reach within the near plane of the eye: drawn again from
    // their back faces (EYE_INSIDE), since their front faces are clipped or behind the eye.
    // An instanced plant's frusta are looked at only where the eye is inside its sphere.
    // (The leaves' spheres follow the frusta's: they are never inside.)
    const auto near_eye = [&](const Sphere& sphere) {
      return glm::length(sphere.centre - f.camera.eye) < sphere.radius + 4 * f.near;
    };
    for (uint32_t i = 0; !mesh && i < world_spheres; ++i)
      if (near_eye(spheres[i])) {
        if (draws.empty()) {
          f.eye_inside.push_back(i);
        } else {
          f.eye_inside.push_back(0);  // the identity instance (world records come first)
          f.eye_inside.push_back(i);
        }
        ++f.eye_inside_frusta;
      }
    for (uint32_t j = 0; !mesh && j < instance_spheres.size(); ++j) {
      if (!near_eye(spheres[world_spheres + j])) continue;
      const InstanceSphere& is = instance_spheres[j];
      const std::vector<Sphere>& local = draw_spheres[is.draw];
      for (uint32_t k = 0; k < local.size(); ++k)
        if (near_eye({is.transform.to_world(local[k].centre), local[k].radius * is.transform.scale})) {
          f.eye_inside.push_back(is.instance);
          f.eye_inside.push_back(draws[is.draw].first_record + k);
          ++f.eye_inside_frusta;
        }
    }
    if (!f.eye_inside.empty()) {
      const size_t bytes = f.eye_inside.size() * sizeof(uint32_t);
      glNamedBufferData(list_buffer.id(), static_cast<GLsizeiptr>(bytes), f.eye_inside.data(), GL_STREAM_DRAW);
      f.stats.frame_bytes_uploaded += bytes;
    }
    f.stats.eye_inside = f.eye_inside_frusta;
    // Ray differentials (texture.h): the next sample to the right / below, one pixel /
    // sqrt(spp) away, as render_cpu.cpp's direction_dx_, direction_dy_.
    f.differential_step = 1 / std::sqrt(static_cast<double>(f.spp));
    f.ray_dx = (f.differential_step * 2 * f.camera.half_width / f.width) * f.camera.right;
    f.ray_dy = (-f.differential_step * 2 * f.camera.half_height / f.height) * f.camera.up;
  }

  // The variants frame `f` draws with, built where this is their first use (the frame's
  // compile time and names).
  void frame_programs(Frame& f) {
    GlFrameStats& s = f.stats;
    f.gbuffer_program = mesh ? 0 : program(frusta_variant(FrustaPass::gbuffer), &s.compile_s, &s.compiled);
    f.inside_program =
        f.eye_inside.empty() ? 0 : program(frusta_variant(FrustaPass::gbuffer_eye_inside), &s.compile_s, &s.compiled);
    f.shadow_program = f.sun_on && !mesh ? program(frusta_variant(FrustaPass::shadow), &s.compile_s, &s.compiled) : 0;
    f.shade_program = program(shade_program(f.sun_on, f.fog_on), &s.compile_s, &s.compiled);
    f.fog_program = f.fog_on ? program(fog_program(f.sun_on, f.fog_mode), &s.compile_s, &s.compiled) : 0;
    f.fog_cones_program = f.fog_cones ? program(fog_cones_program(), &s.compile_s, &s.compiled) : 0;
    s.pass(GlPass::geometry).program = mesh ? mesh->gbuffer_variant() : frusta_variant(FrustaPass::gbuffer).name;
    s.pass(GlPass::shade).program = shade_program(f.sun_on, f.fog_on).name;
    if (f.fog_on) s.pass(GlPass::fog).program = fog_program(f.sun_on, f.fog_mode).name;
    if (f.fog_cones) s.pass(GlPass::fog_cones).program = fog_cones_program().name;
    if (f.sun_on)
      s.pass(GlPass::shadow).program = mesh ? mesh->shadow_variant() : frusta_variant(FrustaPass::shadow).name;
  }

  // The programs' uniforms that stay for the frame: the camera (but its jitter), the ray
  // differentials and the relief's sampling, the sky, ground and materials.
  void frame_uniforms(const Scene& scene, const Frame& f) const {
    for (GLuint p : {f.gbuffer_program, f.inside_program, f.shade_program, f.fog_program, f.fog_cones_program})
      if (p) set_camera_uniforms(p, f.camera_view);
    const ReliefOptions& relief = options.geometry.relief_options;
    for (GLuint p : {f.gbuffer_program, f.inside_program, f.shadow_program}) {
      if (!p) continue;
      set_uniform(p, "u_twist_rad_per_m", options.skin.twist_rad_per_m);
      set_uniform(p, "u_ray_dx", f.ray_dx);
      set_uniform(p, "u_ray_dy", f.ray_dy);
      set_uniform_int(p, "u_relief_linear_steps", std::max(1, relief.linear_steps));
      set_uniform_int(p, "u_relief_bisection_steps", std::max(0, relief.bisection_steps));
      set_uniform_int(p, "u_relief_exact_v", relief.exact_v ? 1 : 0);
      set_uniform(p, "u_relief_max_depth_per_radius", relief.max_depth_per_radius);
      // render_cpu.cpp's pixel_spread_rad: the angle between neighbouring samples' rays.
      set_uniform(p, "u_relief_pixel_spread_rad", glm::length(f.ray_dy));
    }
    const GLuint shade = f.shade_program;
    set_uniform(shade, "u_pixel_step_rad", glm::length(f.ray_dy));
    set_uniform(shade, "u_eye_above_ground", f.camera.eye.y - scene.ground.height);
    set_uniform(shade, "u_sky", scene.sky);
    set_uniform(shade, "u_ground_albedo", scene.ground.albedo);
    // Every slot the scene's table may fill (scene.h material_look; a material with a leaf
    // image gives its segments the image's mean, leaf_images.h segment_look, unless the
    // geometry pass decided their albedo from the image laid on them, bark.glsl); higher
    // indices, which the table cannot describe, default_material_albedo's colour.
    static_assert(gl::kMaxMaterials == kMaterialSlots);
    float albedo[gl::kMaxMaterials * 3], specular[gl::kMaxMaterials];
    const int count = static_cast<int>(kMaterialSlots);
    for (int i = 0; i < count; ++i) {
      const MaterialLook look = segment_look(scene.materials, nullptr, static_cast<uint32_t>(i), leaf_images.get());
      for (int k = 0; k < 3; ++k) albedo[3 * i + k] = static_cast<float>(look.albedo[k]);
      specular[i] = static_cast<float>(look.specular);
    }
    set_uniform_vec3_array(shade, "u_material_albedo", count, albedo);
    set_uniform_float_array(shade, "u_material_specular", count, specular);
    set_uniform_int(shade, "u_material_count", count);
    const double* beyond = default_material_albedo(kMaterialSlots);
    set_uniform(shade, "u_material_albedo_beyond", glm::dvec3(beyond[0], beyond[1], beyond[2]));
    if (f.fog_on) fog_uniforms(scene, f);
  }

  // The medium (heights above the ground: fog.glsl's convention) for shade[FOG] and the fog
  // pass, and the fog pass's frame uniforms.
  void fog_uniforms(const Scene& scene, const Frame& f) const {
    const Fog& fog = *scene.fog;
    const glm::dvec3 sun_centre = glm::normalize(scene.sun.direction);
    for (GLuint p : {f.shade_program, f.fog_program}) {
      set_uniform(p, "u_fog_medium", fog.sigma_s, fog.sigma_a, fog.g, fog.height_falloff);
      set_uniform(p, "u_fog_top", fog.top - scene.ground.height);  // +inf stays +inf
      set_uniform(p, "u_fog_sun_dir", sun_centre);
    }
    const GLuint p = f.fog_program;
    set_uniform(p, "u_eye_above_ground", f.camera.eye.y - scene.ground.height);
    set_uniform(p, "u_sky", scene.sky);
    set_uniform(p, "u_sun_radiance", f.sun_radiance);
    set_uniform_uint(p, "u_steps", f.fog_steps);
    if (f.fog_maps) {
      set_uniform(p, "u_eye_rel_maps", f.camera.eye - fog_maps->origin);
      set_uniform_uint(p, "u_map_count", fog_maps->count);
    }
    if (f.fog_mode == GlFogMode::brute || f.fog_mode == GlFogMode::map) return;
    set_uniform_int(p, "u_cones", f.fog_cones ? 1 : 0);
    if (!f.fog_cones) return;
    const GLuint c = f.fog_cones_program;
    set_uniform(c, "u_eye_rel_cones", f.camera.eye - fog_cones->origin);
    set_uniform(c, "u_eye_above_ground", f.camera.eye.y - scene.ground.height);
    set_uniform_uint(c, "u_fog_capacity", fog_lists.capacity);
  }

  // The buffers and textures every pass reads (bindings.h), and the state every pass
  // starts from.
  void bind_frame(const Frame& f) const {
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glBindVertexArray(vao.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kSegmentsBinding, segment_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kSegmentIdsBinding, id_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kSegmentListBinding, list_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kInstancesBinding, instance_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kCrotchesBinding, crotch_buffer.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kCrotchListsBinding, crotch_list_buffer.id());
    bark_maps->bind();
    glBindTextureUnit(gl::kGNormalDistanceUnit, targets.gbuffer[0].id());
    glBindTextureUnit(gl::kGGeometricUUnit, targets.gbuffer[1].id());
    glBindTextureUnit(gl::kGIdsUnit, targets.gbuffer[2].id());
    glBindTextureUnit(gl::kGAlbedoUnit, targets.gbuffer[3].id());
    glBindTextureUnit(gl::kShadowMapUnit, f.sun_on ? shadow_map.map.id() : 0);
    glBindTextureUnit(gl::kAccumulationUnit, targets.accumulation.id());
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glFrontFace(GL_CCW);
  }

  void take_mesh_spheres() { spheres = mesh->bounding_spheres(); }

  // The leaves' spheres after the frusta's (or the mesh's): the near plane and the shadow
  // map's frame hold them too.
  void add_leaf_spheres() {
    if (leaves) spheres.insert(spheres.end(), leaves->bounding_spheres().begin(), leaves->bounding_spheres().end());
  }
};

// ---- Construction: what is uploaded once -------------------------------------------------

GlRenderer::GlRenderer(const Scene& scene, const RenderOptions& options, std::shared_ptr<GlProgramCache> programs)
    : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.options = options;
  st.program_cache = programs ? std::move(programs) : std::make_shared<GlProgramCache>();
  if (scene.plants.size() >= gl::kMaxPlants) throw GlError("the GL backend draws at most 2^24 plants");
  if (auto why = gl_unsupported(scene, options)) throw GlError(*why);
  st.plant_count = scene.plants.size();

  // Bark images first: the relief's shells set the pyramids' bounding spheres.
  Clock::time_point start = Clock::now();
  st.bark_maps = std::make_unique<GlBarkMaps>(scene, options);
  st.pending_plant_bytes += st.bark_maps->uploaded_bytes();
  st.features.want_uv = (options.aovs & kAovUv) != 0;
  st.features.relief = st.bark_maps->relief();
  st.features.bark = st.bark_maps->albedo();
  st.features.texture_units = static_cast<int>(st.bark_maps->images());
  if (st.bark_maps->images() > 0)
    st.setup_passes.push_back({"textures", seconds_since(start),
                               std::to_string(st.bark_maps->images()) + " images, " +
                                   std::to_string(st.bark_maps->texture_bytes() / 1024) + " KiB with MIP chains"});

  start = Clock::now();
  std::vector<GpuSegment> records;
  std::vector<uint32_t> ids;  // plant, chain, segment, 0 per frustum
  std::vector<GpuInstance> instances;
  if (options.geometry.kind == GeometryKind::mesh) {
    // The polygon baseline (gl_mesh.h): its own skin, tessellate, displace, upload, programs.
    st.mesh = std::make_unique<GlMesh>(scene, options, st.bark_maps->albedo() ? st.features.texture_units : 0);
    st.take_mesh_spheres();
    st.frusta = st.mesh->frusta();
    st.setup_passes = st.mesh->setup_passes();
  } else {
    st.skin_plants(scene, &records, &ids, &instances);
    std::string detail = std::to_string(scene.plants.size()) + " plants, " + std::to_string(st.frusta) + " frusta";
    if (!st.draws.empty())
      detail += "; " + std::to_string(st.instanced_plants) + " plants as instances of " +
                std::to_string(st.draws.size() - (instances.front().own ? 1 : 0)) + " skeletons, " +
                std::to_string(records.size()) + " frusta skinned";
    st.setup_passes.push_back({"skin", seconds_since(start), detail});
  }

  start = Clock::now();
  st.vao = make_gl_vertex_array();
  // The segment records may be rewritten in place (update_plants).
  st.segment_buffer = make_gl_buffer(records.data(), records.size() * sizeof(GpuSegment), GL_DYNAMIC_STORAGE_BIT);
  st.id_buffer = make_gl_buffer(ids.data(), ids.size() * sizeof(uint32_t));
  st.instance_buffer = make_gl_buffer(instances.data(), instances.size() * sizeof(GpuInstance));
  const uint64_t crotch_bytes = st.upload_crotch_fade(records);
  GLuint list = 0;
  glCreateBuffers(1, &list);  // mutable storage: a new list each frame that needs one
  st.list_buffer.reset(list);
  check_gl("upload");
  if (st.mesh) {
    st.uploaded_bytes = st.mesh->gpu_bytes();  // its "upload" pass is in already
  } else {
    st.uploaded_bytes = records.size() * sizeof(GpuSegment) + ids.size() * sizeof(uint32_t) +
                        instances.size() * sizeof(GpuInstance) + crotch_bytes;
    st.setup_passes.push_back({"upload", seconds_since(start),
                               std::to_string(st.uploaded_bytes / 1024) + " KiB: " + std::to_string(records.size()) +
                                   " GpuSegment records (64 B) + ids (16 B)" +
                                   (instances.empty() ? std::string()
                                                      : " + " + std::to_string(instances.size()) + " instances (48 B)") +
                                   (crotch_bytes == 0 ? std::string()
                                                      : " + " + std::to_string(st.fade_crotches.size()) +
                                                            " crotches' relief fade")});
  }
  // The crotches' fillets beside the ray-cast frusta (gl_mesh.h fillets_of; the mesh has
  // its own in its triangles).
  if (!st.mesh) {
    st.fillets = GlMesh::fillets_of(scene, options, st.bark_maps->albedo() ? st.features.texture_units : 0);
    if (st.fillets) {
      st.uploaded_bytes += st.fillets->gpu_bytes();
      for (RenderPass pass : st.fillets->setup_passes()) {
        pass.name = "fillets " + pass.name;
        st.setup_passes.push_back(std::move(pass));
      }
    }
  }
  // The leaves (gl_mesh.h leaves_of): their own upload and programs.
  st.leaf_images = scene_leaf_images(scene);
  st.leaves = GlMesh::leaves_of(scene, options, st.leaf_images);
  if (st.leaves) {
    st.add_leaf_spheres();
    st.uploaded_bytes += st.leaves->gpu_bytes();
    for (RenderPass pass : st.leaves->setup_passes()) {
      pass.name = "leaves " + pass.name;
      st.setup_passes.push_back(std::move(pass));
    }
  }
  st.pending_plant_bytes += st.uploaded_bytes;

  // What every frame needs; EYE_INSIDE is built when a frame needs it.
  double compile_s = 0;
  const bool sun_on = sun_shines(scene);
  std::string names;
  const bool fog_on = scene.fog.has_value();
  std::vector<ShaderProgramSource> needed = {st.frusta_variant(FrustaPass::gbuffer), shade_program(sun_on, fog_on)};
  if (sun_on) needed.push_back(st.frusta_variant(FrustaPass::shadow));
  if (st.mesh) needed = {shade_program(sun_on, fog_on)};  // the mesh built its own
  if (fog_on) needed.push_back(fog_program(sun_on));
  for (const ShaderProgramSource& source : needed) st.program(source, &compile_s, &names);
  st.setup_passes.push_back({"programs", compile_s, names});
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  check_gl("setup");
}

GlRenderer::~GlRenderer() = default;

void GlRenderer::set_conservative_depth(bool on) { state_->features.conservative_depth = on; }

uint64_t GlRenderer::set_fog_maps(std::span<const SunDepthMap> maps) {
  state_->fog_maps = upload_fog_maps(maps);
  check_gl("set_fog_maps");
  return state_->fog_maps->bytes;
}

uint64_t GlRenderer::set_fog_cones(const ConeSet& cones) {
  state_->fog_cones = upload_fog_cones(cones);
  check_gl("set_fog_cones");
  return state_->fog_cones->bytes;
}

void GlRenderer::set_shadow_map_texels(uint32_t texels) {
  if (texels == 0) {
    state_->shadow_texels_override = 0;
    return;
  }
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  state_->shadow_texels_override = std::clamp<uint32_t>(texels, 16, static_cast<uint32_t>(max_size));
}

uint64_t GlRenderer::frusta() const { return state_->frusta; }
uint64_t GlRenderer::uploaded_bytes() const { return state_->uploaded_bytes; }
const std::vector<RenderPass>& GlRenderer::setup_passes() const { return state_->setup_passes; }

uint64_t GlRenderer::update_plants(const Scene& scene) {
  State& st = *state_;
  if (scene.plants.size() != st.plant_count)
    throw std::invalid_argument("GlRenderer::update_plants: the scene has " + std::to_string(scene.plants.size()) +
                                " plants, the renderer " + std::to_string(st.plant_count));
  // The leaves are uploaded again whole (they move with their joints: animate.h).
  const uint64_t leaf_bytes = (st.leaves ? st.leaves->update(scene) : 0) + (st.fillets ? st.fillets->update(scene) : 0);
  if (st.mesh) {  // the polygon baseline is re-tessellated and uploaded whole
    const uint64_t uploaded = st.mesh->update(scene) + leaf_bytes;
    st.take_mesh_spheres();
    st.add_leaf_spheres();
    st.frusta = st.mesh->frusta();
    st.uploaded_bytes = st.mesh->gpu_bytes() + (st.leaves ? st.leaves->gpu_bytes() : 0);
    st.pending_plant_bytes += uploaded;
    return uploaded;
  }
  std::vector<GpuSegment> records;
  std::vector<uint32_t> ids;
  std::vector<GpuInstance> instances;
  const uint64_t old_records = st.record_count;
  const bool was_instanced = !st.draws.empty();
  st.skin_plants(scene, &records, &ids, &instances);
  st.add_leaf_spheres();
  const size_t record_bytes = records.size() * sizeof(GpuSegment);
  const uint64_t crotch_bytes = st.upload_crotch_fade(records);  // the crotches move with the frusta
  uint64_t uploaded = record_bytes + leaf_bytes + crotch_bytes;
  if (!was_instanced && st.draws.empty() && records.size() == old_records) {
    update_gl_buffer(st.segment_buffer, records.data(), record_bytes);
  } else {
    // The topology changed (a frustum more or less, or which plants share a skeleton):
    // new buffers, ids and instances included.
    const size_t instance_bytes = instances.size() * sizeof(GpuInstance);
    st.segment_buffer = make_gl_buffer(records.data(), record_bytes, GL_DYNAMIC_STORAGE_BIT);
    st.id_buffer = make_gl_buffer(ids.data(), ids.size() * sizeof(uint32_t));
    st.instance_buffer = make_gl_buffer(instances.data(), instance_bytes);
    uploaded += ids.size() * sizeof(uint32_t) + instance_bytes;
    st.uploaded_bytes =
        record_bytes + ids.size() * sizeof(uint32_t) + instance_bytes + (st.leaves ? st.leaves->gpu_bytes() : 0) +
        (st.fillets ? st.fillets->gpu_bytes() : 0) + crotch_bytes;
  }
  check_gl("update_plants");
  st.pending_plant_bytes += uploaded;
  return uploaded;
}

// ---- A frame ------------------------------------------------------------------------------

const GlFrameStats& GlRenderer::draw(const Scene& scene) { return draw_frame(scene, nullptr); }

const GlFrameStats& GlRenderer::draw(const Scene& scene, const GlTarget& target) {
  if (target.width != scene.width || target.height != scene.height)
    throw std::invalid_argument("GlRenderer::draw: the target is " + std::to_string(target.width) + "x" +
                                std::to_string(target.height) + ", the frame " + std::to_string(scene.width) + "x" +
                                std::to_string(scene.height));
  check_gl_framebuffer(target.framebuffer, "GlRenderer::draw target");
  return draw_frame(scene, &target);
}

const GlFrameStats& GlRenderer::draw_frame(const Scene& scene, const GlTarget* target) {
  State& st = *state_;
  Frame f;
  f.start = Clock::now();
  begin_frame(scene, f);

  // The CPU's stratified grid, one offset per sample for every pixel; the sun's disc
  // sampled as the CPU's sun_sample does (uniform in solid angle). The shadow map is
  // redrawn per sample only where the sun direction moves (a disc sun at spp > 1).
  const glm::dvec3 sun_direction = glm::normalize(scene.sun.direction);
  const AxisFrame sun_frame = axis_frame(sun_direction);
  const double cos_alpha = std::cos(scene.sun.angular_radius_deg * kPi / 180);
  const bool sun_per_sample = f.sun_on && f.spp > 1 && scene.sun.angular_radius_deg > 0;
  const uint32_t grid_x = static_cast<uint32_t>(std::ceil(std::sqrt(static_cast<double>(f.spp))));
  const uint32_t grid_y = (f.spp + grid_x - 1) / grid_x;
  const float black[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(st.targets.accumulation_fbo.id(), GL_COLOR, 0, black);
  for (uint32_t sample = 0; sample < f.spp; ++sample) {
    if (st.options.progress.cancelled()) {
      f.stats.cancelled = true;
      break;
    }
    render_common::SampleRng rng(0x5EED0000ull + sample * 0x9E37ull);
    double jitter_x = 0.5, jitter_y = 0.5;
    if (f.spp > 1) {
      jitter_x = ((sample % grid_x) + rng.next_double()) / grid_x;
      jitter_y = ((sample / grid_x) + rng.next_double()) / grid_y;
    }
    const glm::dvec3 l =
        sun_per_sample ? render_common::sample_sun_disc(sun_direction, cos_alpha, sun_frame, rng) : sun_direction;
    if (f.sun_on && (sample == 0 || sun_per_sample)) shadow_pass(f, l);
    geometry_pass(f, jitter_x, jitter_y);
    shade_pass(f, l);
    if (f.fog_cones) fog_cones_pass(f);
    if (f.fog_on) fog_pass(f, sample, false);
  }
  // AOVs describe the pixel centres: the last G-buffer (and fog AOV) already is that at 1
  // spp. Else the fog AOV's stream is sample spp's, as on the CPU.
  if (!f.stats.cancelled && st.options.aovs && f.spp > 1) {
    geometry_pass(f, 0.5, 0.5);
    if (f.fog_on && (st.options.aovs & kAovFog)) {
      if (f.fog_cones) fog_cones_pass(f);
      fog_pass(f, f.spp, true);
    }
  }
  if (target && !f.stats.cancelled) present_pass(f, *target);
  end_frame(f);
  return st.last;
}

// Everything a frame's passes share, before the first: its stats' counts, the targets at
// its size, the camera and near plane, the programs, their frame uniforms, the bindings.
void GlRenderer::begin_frame(const Scene& scene, Frame& f) {
  State& st = *state_;
  GlFrameStats& s = f.stats;
  s.frame = ++st.frames;
  f.width = scene.width;
  f.height = scene.height;
  f.spp = std::max(1u, st.options.spp);
  s.width = f.width;
  s.height = f.height;
  s.spp = f.spp;
  s.geometry = st.mesh ? GeometryKind::mesh : GeometryKind::frusta;
  s.geometry_label = st.mesh ? st.mesh->label() : "";
  s.frusta = st.frusta;
  s.triangles = st.mesh ? st.mesh->triangles() : 0;
  s.geometry_bytes = st.uploaded_bytes;
  s.plant_bytes_uploaded = std::exchange(st.pending_plant_bytes, 0);
  if (auto why = gl_fog_unsupported(scene, st.options)) throw GlError(*why);
  f.fog_on = scene.fog.has_value();
  if (f.fog_on) {
    f.fog_mode = *gl_fog_mode_of(requested_fog_mode(scene, st.options));
    const bool cone_mode = f.fog_mode == GlFogMode::medium || f.fog_mode == GlFogMode::fast;
    if (cone_mode && !st.fog_cones)
      throw GlError("the GL fog pass's cone modes (medium, fast) need shadow cones (GlRenderer::set_fog_cones; render_gl builds them)");
    if (f.fog_mode == GlFogMode::map && !st.fog_maps)
      throw GlError("the GL fog pass's mode map needs sun maps (GlRenderer::set_fog_maps; render_gl takes options.fog.maps)");
    f.fog_cones = cone_mode && st.fog_cones;
    f.fog_maps = f.fog_mode == GlFogMode::map;
    if (f.fog_maps) s.fog_map_bytes = st.fog_maps->bytes;
    f.fog_steps = std::clamp(st.options.fog.steps.value_or(scene.fog->steps), 1u, kFogMaxSteps);
    s.fog_mode = gl_fog_mode_name(f.fog_mode);
    s.fog_steps = f.fog_steps;
    if (f.fog_cones) {
      // Two nodes a pixel to start with, then what the largest pass so far asked for.
      const uint32_t pixels = f.width * f.height;
      s.targets_allocated += st.fog_lists.reserve(pixels, std::max({2 * pixels, st.fog_nodes_wanted, 1u}));
      s.fog_cones = st.fog_cones->count;
      s.fog_list_capacity = st.fog_lists.capacity;
    }
  }
  // G-buffer, accumulation (and the fog AOV)
  s.targets_allocated += st.targets.resize(f.width, f.height, f.fog_on) ? (f.fog_on ? 3 : 2) : 0;
  f.sun_on = sun_shines(scene);
  f.sun_radiance = scene.sun.radiance;
  if (f.sun_on) {
    s.shadow_texels = st.shadow_texels_override ? st.shadow_texels_override : st.shadow_map_texels(f.width, f.height);
    s.targets_allocated += st.shadow_map.resize(s.shadow_texels) ? 1 : 0;
  }
  s.target_bytes = st.targets.bytes() + (f.sun_on ? st.shadow_map.bytes() : 0) + (f.fog_cones ? st.fog_lists.bytes() : 0);
  st.frame_views(scene, f);
  st.frame_programs(f);
  st.frame_uniforms(scene, f);
  st.bind_frame(f);
  if (f.fog_cones) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogConesBinding, st.fog_cones->records.id());
    st.fog_lists.bind();
    st.fog_lists.clear_frame();
  }
  if (f.fog_maps) st.fog_maps->bind();
  st.timers.begin_frame(s.frame);
}

// The shadow map for sun direction `l`: the frusta ray cast (or the mesh rasterised),
// depth only, in the orthographic view along `l` that holds every plant.
void GlRenderer::shadow_pass(Frame& f, const glm::dvec3& l) {
  State& st = *state_;
  f.shadow = shadow_frame(st.spheres, l, f.stats.shadow_texels);
  const GlSunView view = sun_view(f.shadow, f.stats.shadow_texels);
  st.timers.begin(GlPass::shadow);
  ++f.stats.pass(GlPass::shadow).runs;
  const GLuint fbo = st.shadow_map.fbo.id();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, static_cast<GLsizei>(f.stats.shadow_texels), static_cast<GLsizei>(f.stats.shadow_texels));
  const float one = 1;
  glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  if (st.mesh) {
    st.mesh->draw_shadow(view);
  } else {
    set_sun_view_uniforms(f.shadow_program, view);
    glUseProgram(f.shadow_program);
    st.draw_frusta(f.shadow_program);
  }
  if (st.fillets) st.fillets->draw_shadow(view);
  if (st.leaves) st.leaves->draw_shadow(view);
  st.timers.end();
}

// The G-buffer of one sample at (jitter_x, jitter_y) in its pixel: the frusta ray cast
// (front faces; those around the eye again from their back faces), or the mesh rasterised.
void GlRenderer::geometry_pass(Frame& f, double jitter_x, double jitter_y) {
  State& st = *state_;
  f.camera_view.jitter = glm::vec2(static_cast<float>(jitter_x), static_cast<float>(jitter_y));
  st.timers.begin(GlPass::geometry);
  ++f.stats.pass(GlPass::geometry).runs;
  const GLuint fbo = st.targets.gbuffer_fbo.id();
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, static_cast<GLsizei>(f.width), static_cast<GLsizei>(f.height));
  const float miss[4] = {0, 0, 0, -1}, zero[4] = {0, 0, 0, 0}, far_depth = 0;
  const GLuint zero_ids[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(fbo, GL_COLOR, 0, miss);
  glClearNamedFramebufferfv(fbo, GL_COLOR, 1, zero);
  glClearNamedFramebufferuiv(fbo, GL_COLOR, 2, zero_ids);
  glClearNamedFramebufferfv(fbo, GL_COLOR, 3, zero);
  glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &far_depth);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  if (st.mesh) {
    st.mesh->draw_gbuffer(f.camera_view, f.differential_step);
  } else {
    set_jitter_uniform(f.gbuffer_program, f.camera_view.jitter);
    glUseProgram(f.gbuffer_program);
    st.draw_frusta(f.gbuffer_program);
    if (f.inside_program) {
      glCullFace(GL_FRONT);
      set_jitter_uniform(f.inside_program, f.camera_view.jitter);
      glUseProgram(f.inside_program);
      glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(f.eye_inside_frusta * gl::kPyramidVertices));
    }
  }
  if (st.fillets) st.fillets->draw_gbuffer(f.camera_view, f.differential_step);
  if (st.leaves) st.leaves->draw_gbuffer(f.camera_view, f.differential_step);
  st.timers.end();
}

// Shades the G-buffer for sun direction `l` with the last shadow map and adds the result
// into the accumulation target.
void GlRenderer::shade_pass(Frame& f, const glm::dvec3& l) {
  State& st = *state_;
  const GLuint shade = f.shade_program;
  set_jitter_uniform(shade, f.camera_view.jitter);
  if (f.sun_on) {
    const ShadowFrame& v = f.shadow;
    set_sun_view_uniforms(shade, sun_view(v, f.stats.shadow_texels));  // the map's frame
    set_uniform(shade, "u_sun_dir", l);
    set_uniform(shade, "u_sun_radiance", f.sun_radiance);
    set_uniform(shade, "u_eye_rel_light", f.camera.eye - v.centre);
    set_uniform(shade, "u_normal_offset_m", kShadowNormalOffsetTexels * v.texel_m);
    set_uniform(shade, "u_depth_bias", kShadowDepthBiasTexels * v.texel_m / v.s_range);
  }
  st.timers.begin(GlPass::shade);
  ++f.stats.pass(GlPass::shade).runs;
  glBindFramebuffer(GL_FRAMEBUFFER, st.targets.accumulation_fbo.id());
  glViewport(0, 0, static_cast<GLsizei>(f.width), static_cast<GLsizei>(f.height));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glUseProgram(shade);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDisable(GL_BLEND);
  st.timers.end();
}

// The shadow cones' intervals along each pixel's ray of this sample, clipped to what its
// G-buffer sees, appended to the pixel's list: every cone's bounding pyramid drawn from its
// back faces (fog_cones.frag.glsl says why), no depth test, no colour.
void GlRenderer::fog_cones_pass(Frame& f) {
  State& st = *state_;
  const GLuint cones = f.fog_cones_program;
  set_jitter_uniform(cones, f.camera_view.jitter);
  st.fog_lists.clear_pass();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  st.timers.begin(GlPass::fog_cones);
  ++f.stats.pass(GlPass::fog_cones).runs;
  const GLuint fbo = st.targets.fog_fbo.id();
  const GLenum none[2] = {GL_NONE, GL_NONE};
  glNamedFramebufferDrawBuffers(fbo, 2, none);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, static_cast<GLsizei>(f.width), static_cast<GLsizei>(f.height));
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_FRONT);
  glUseProgram(cones);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(st.fog_cones->count * gl::kPyramidVertices));
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  st.timers.end();
}

// The fog's in-scatter along each pixel's ray of this sample (its G-buffer, the last shadow
// map) added into the accumulation, and its fog AOV; `aov_only`: the AOV alone (the pixel
// centres' pass at spp > 1). `sample` picks the jitter's random stream.
void GlRenderer::fog_pass(Frame& f, uint32_t sample, bool aov_only) {
  State& st = *state_;
  const GLuint fog = f.fog_program;
  set_jitter_uniform(fog, f.camera_view.jitter);
  set_uniform_uint(fog, "u_seed", sample);
  if (f.sun_on) {
    const ShadowFrame& v = f.shadow;
    set_sun_view_uniforms(fog, sun_view(v, f.stats.shadow_texels));
    set_uniform(fog, "u_eye_rel_light", f.camera.eye - v.centre);
    set_uniform(fog, "u_depth_bias", kShadowDepthBiasTexels * v.texel_m / v.s_range);
  }
  st.timers.begin(GlPass::fog);
  ++f.stats.pass(GlPass::fog).runs;
  const GLuint fbo = st.targets.fog_fbo.id();
  const GLenum both[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1}, aov[2] = {GL_NONE, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(fbo, 2, aov_only ? aov : both);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, static_cast<GLsizei>(f.width), static_cast<GLsizei>(f.height));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glEnablei(GL_BLEND, 0);  // in-scatter added to the beauty; the AOV written
  glBlendFunci(0, GL_ONE, GL_ONE);
  glDisablei(GL_BLEND, 1);
  glUseProgram(fog);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDisable(GL_BLEND);
  st.timers.end();
}

// The accumulated beauty ÷ spp into the caller's target (gl_target.h).
void GlRenderer::present_pass(Frame& f, const GlTarget& target) {
  State& st = *state_;
  const ShaderProgramSource source = present_program(target.encoding == GlTargetEncoding::srgb);
  f.present_program = st.program(source, &f.stats.compile_s, &f.stats.compiled);
  f.stats.pass(GlPass::present).program = source.name;
  f.stats.presented = true;
  set_uniform(f.present_program, "u_inv_samples", 1.0f / static_cast<float>(f.spp));
  st.timers.begin(GlPass::present);
  ++f.stats.pass(GlPass::present).runs;
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
  glViewport(0, 0, static_cast<GLsizei>(target.width), static_cast<GLsizei>(target.height));
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glUseProgram(f.present_program);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  st.timers.end();
}

// Submits the frame (glFlush: the GPU starts, nobody waits) and files its stats.
void GlRenderer::end_frame(Frame& f) {
  State& st = *state_;
  st.timers.end_frame();
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glBindVertexArray(0);
  check_gl("frame");
  glFlush();
  f.stats.cpu_s = seconds_since(f.start);
  st.last = std::move(f.stats);
  st.in_flight.push_back(st.last);
  take_timed_frames(false);
}

// Merges the GPU times that have arrived (all of them, waiting, when `wait`) into the
// frames in flight; the newest complete one becomes timed_frame's.
void GlRenderer::take_timed_frames(bool wait) {
  State& st = *state_;
  for (const GlPassTimers::FrameTimes& times : wait ? st.timers.collect_all() : st.timers.collect_ready()) {
    auto found = std::find_if(st.in_flight.begin(), st.in_flight.end(),
                              [&](const GlFrameStats& s) { return s.frame == times.frame; });
    if (found == st.in_flight.end()) continue;
    for (size_t p = 0; p < kGlPassCount; ++p) found->passes[p].gpu_s = times.seconds[p];
    found->gpu_times_ready = true;
    if (found->frame == st.last.frame) st.last = *found;
    st.newest_timed = std::move(*found);
    st.in_flight.erase(found);
  }
}

std::optional<GlFrameStats> GlRenderer::timed_frame() {
  take_timed_frames(false);
  return std::exchange(state_->newest_timed, std::nullopt);
}

const GlFrameStats& GlRenderer::wait_for_frame() {
  State& st = *state_;
  if (st.frames == 0) throw std::logic_error("GlRenderer::wait_for_frame: no frame drawn yet");
  if (!st.last.gpu_times_ready) take_timed_frames(true);
  if (st.last.fog_cones > 0 && !st.last.fog_counted) {
    // The GPU is done with the frame: its counters are the last frame's.
    const gl::GlFogCounters c = st.fog_lists.read_counters();
    st.last.fog_fragments = c.fragments;
    st.last.fog_overflow_fragments = c.overflow_fragments;
    st.last.fog_overflow_pixels = c.overflow_pixels;
    st.last.fog_largest_pass = c.largest_pass;
    st.last.fog_counted = true;
    st.fog_nodes_wanted = std::max(st.fog_nodes_wanted, c.largest_pass + c.largest_pass / 4);
  }
  return st.last;
}

// ---- Reading back -------------------------------------------------------------------------

RenderImage GlRenderer::read_back() {
  State& st = *state_;
  if (st.frames == 0) throw std::logic_error("GlRenderer::read_back: no frame drawn yet");
  const uint32_t w = st.targets.width, h = st.targets.height;
  const uint32_t aovs = st.options.aovs;
  const size_t pixels = static_cast<size_t>(w) * h;
  RenderImage image;
  image.width = w;
  image.height = h;
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  // GL's rows run bottom-up: flipped here.
  std::vector<float> rgba(pixels * 4);
  glGetTextureImage(st.targets.accumulation.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.size() * sizeof(float)),
                    rgba.data());
  image.beauty.resize(pixels * 4);
  const float inv_spp = 1.0f / static_cast<float>(std::max(1u, st.options.spp));
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const float* src = &rgba[(static_cast<size_t>(h - 1 - y) * w + x) * 4];
      float* dst = &image.beauty[(static_cast<size_t>(y) * w + x) * 4];
      for (int k = 0; k < 3; ++k) dst[k] = src[k] * inv_spp;
      dst[3] = 1;
    }
  if (aovs) {
    std::vector<float> g0(pixels * 4), g1(pixels * 4);
    std::vector<uint32_t> g2(pixels * 4);
    glGetTextureImage(st.targets.gbuffer[0].id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(g0.size() * sizeof(float)),
                      g0.data());
    glGetTextureImage(st.targets.gbuffer[1].id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(g1.size() * sizeof(float)),
                      g1.data());
    glGetTextureImage(st.targets.gbuffer[2].id(), 0, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                      static_cast<GLsizei>(g2.size() * sizeof(uint32_t)), g2.data());
    if (aovs & kAovDepth) image.depth.assign(pixels, 0.0f);
    if (aovs & kAovNormal) image.normal.assign(pixels * 3, 0.0f);
    if (aovs & kAovUv) image.uv.assign(pixels * 2, 0.0f);
    if (aovs & kAovId) image.id.assign(pixels * 3, 0.0f);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        const size_t src = static_cast<size_t>(h - 1 - y) * w + x, dst = static_cast<size_t>(y) * w + x;
        const bool hit = g0[src * 4 + 3] >= 0;
        if (!image.depth.empty()) image.depth[dst] = hit ? g0[src * 4 + 3] : std::numeric_limits<float>::infinity();
        if (!image.normal.empty())
          for (int k = 0; k < 3; ++k) image.normal[dst * 3 + k] = hit ? g0[src * 4 + k] : 0.0f;
        if (!image.uv.empty() && hit) {
          float v_m = 0;
          std::memcpy(&v_m, &g2[src * 4 + 3], sizeof v_m);
          image.uv[dst * 2 + 0] = g1[src * 4 + 3];
          image.uv[dst * 2 + 1] = v_m;
        }
        if (!image.id.empty()) {
          image.id[dst * 3 + 0] = hit ? static_cast<float>(g2[src * 4 + 0] & gl::kPlantIndexMask) : -1.0f;
          // A leaf: kAovLeafChain (render_types.h), segment its index in the plant's leaves.
          const uint32_t chain = g2[src * 4 + 1];
          image.id[dst * 3 + 1] = !hit ? -1.0f : chain == gl::kLeafChain ? kAovLeafChain : static_cast<float>(chain);
          image.id[dst * 3 + 2] = hit ? static_cast<float>(g2[src * 4 + 2]) : -1.0f;
        }
      }
  }
  if ((aovs & kAovFog) && st.targets.fog) {
    std::vector<float> fog(pixels * 4);
    glGetTextureImage(st.targets.fog_aov.id(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(fog.size() * sizeof(float)),
                      fog.data());
    image.fog.resize(pixels * 4);
    for (uint32_t y = 0; y < h; ++y)
      std::memcpy(&image.fog[static_cast<size_t>(y) * w * 4], &fog[static_cast<size_t>(h - 1 - y) * w * 4],
                  w * 4 * sizeof(float));
  }
  check_gl("readback");
  return image;
}

RenderResult GlRenderer::render(const Scene& scene) {
  const Clock::time_point start = Clock::now();
  RenderResult result;
  const GlFrameStats& drawn = draw(scene);
  result.frusta = drawn.frusta;
  result.geometry_bytes = drawn.geometry_bytes;
  if (drawn.cancelled) {
    result.cancelled = true;
    return result;
  }
  // After the GPU's answer: "readback" is the transfer alone.
  const GlFrameStats* waited = &wait_for_frame();
  if (waited->fog_overflow_fragments > 0) {
    // The cone intervals overflowed their lists (those pixels were marched whole, as
    // brute): drawn once more, the lists now sized by what the first frame asked for.
    const GlFrameStats& again = draw(scene);
    if (again.cancelled) {
      result.cancelled = true;
      return result;
    }
    waited = &wait_for_frame();
  }
  const GlFrameStats& stats = *waited;
  const Clock::time_point readback_start = Clock::now();
  result.image = read_back();
  const double readback_s = seconds_since(readback_start);
  result.passes = describe_frame(stats);
  result.passes.push_back({"readback", readback_s, std::to_string(stats.width) + "x" + std::to_string(stats.height)});
  result.passes.push_back({"frame (wall)", seconds_since(start), ""});
  result.primary_rays = static_cast<uint64_t>(stats.width) * stats.height * stats.spp;
  result.shadow_rays = 0;
  return result;
}

RenderResult render_gl(const Scene& scene, const RenderOptions& options, GlFrameStats* stats, const GlConeSource& cones) {
  if (auto why = gl_unsupported(scene, options)) throw GlError(*why);
  std::optional<GlRenderer> built;
  try {
    built.emplace(scene, options);
  } catch (const GlCancelled&) {  // cancelled while skinning: flagged, as render_cpu does
    RenderResult cancelled;
    cancelled.cancelled = true;
    return cancelled;
  }
  GlRenderer& renderer = *built;
  std::vector<RenderPass> cone_passes;
  if (scene.fog && gl_fog_walks_maps(requested_fog_mode(scene, options))) {
    // Mode map: the caller's sun maps (the CPU builds them, app/front/render.h), uploaded once.
    if (options.fog.maps.empty())
      throw GlError("the GL fog pass's mode map needs sun maps (render_gl's options.fog.maps)");
    const Clock::time_point start = Clock::now();
    const uint64_t bytes = renderer.set_fog_maps(options.fog.maps);
    cone_passes.push_back({"map upload", seconds_since(start),
                           std::to_string(options.fog.maps.size()) + " maps, " + std::to_string(bytes >> 10) + " KiB"});
  } else if (scene.fog && requested_fog_mode(scene, options) != FogMode::brute) {
    // The cone modes: the caller's shadow cones (the CPU's sun photons), uploaded once.
    if (!cones)
      throw GlError("the GL fog pass's cone modes (medium, fast) need shadow cones (render_gl's cone source)");
    const FogMode mode = requested_fog_mode(scene, options) == FogMode::medium ? FogMode::medium : FogMode::fast;
    const std::shared_ptr<const ConeSet> made = cones(mode, cone_passes);
    if (!made) {
      RenderResult cancelled;
      cancelled.cancelled = true;
      return cancelled;
    }
    const Clock::time_point start = Clock::now();
    const uint64_t bytes = renderer.set_fog_cones(*made);
    cone_passes.push_back({"cone upload", seconds_since(start),
                           std::to_string(made->size()) + " cones, " + std::to_string(bytes / 1024) + " KiB"});
  }
  RenderResult result = renderer.render(scene);
  result.passes.insert(result.passes.begin(), cone_passes.begin(), cone_passes.end());
  if (stats) *stats = renderer.wait_for_frame();
  result.passes.insert(result.passes.begin(), renderer.setup_passes().begin(), renderer.setup_passes().end());
  return result;
}

}  // namespace sylva
