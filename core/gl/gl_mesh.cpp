// gl_mesh.cpp — the polygon baseline on the GPU (Bhagvat et al. 2009 sec. 4: the GS and GS+R
// columns the ray caster is raced against): the CPU mesh path's triangles (tessellate.h,
// displace), uploaded once and rasterised into the ray caster's G-buffer. See gl_mesh.h.
#include "core/gl/gl_mesh.h"

#include "core/geometry/crotch_mesh.h"

#include <algorithm>
#include <climits>
#include <cstddef>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>

#include "core/gl/bindings.h"
#include "core/gl/gl_api.h"
#include "core/gl/gl_instances.h"
#include "core/gl/gl_objects.h"
#include "core/gl/gl_program.h"
#include "core/gl/gl_views.h"
#include "core/scene/culling.h"
#include "core/scene/render_common.h"
#include "core/scene/height_maps.h"
#include "core/scene/leaf_images.h"
#include "core/geometry/leaf_mesh.h"
#include "core/geometry/plant_mesh.h"
#include "core/util/clock.h"

namespace sylva {

namespace {


// One vertex as mesh.vert.glsl reads it (attributes 0–3).
struct MeshVertex {
  float position[3];  // metres, relative to the plant's origin_hi
  float normal[3];    // unit shading normal
  float uv[2];        // u turns, v_m metres
  uint32_t frustum;   // index into the frustum records
};
static_assert(sizeof(MeshVertex) == 36);

using gl::MeshFrustumRecord;

// What is uploaded, built on the CPU.
struct MeshArrays {
  std::vector<MeshVertex> vertices;
  std::vector<uint32_t> indices;
  std::vector<MeshFrustumRecord> frusta;
  std::vector<GlMeshSphere> spheres;
  uint32_t displaced_plants = 0;
};

// Appends plant `plant`'s mesh `part` (tessellated from `skinned`) to `out`, a sphere per
// frustum to *spheres.
void append_plant(MeshArrays& out, const TriangleMesh& part, const SkinnedSkeleton& skinned, uint32_t plant,
                  std::vector<GlMeshSphere>* spheres) {
  if (part.positions.empty()) return;
  if (out.vertices.size() + part.positions.size() > std::numeric_limits<uint32_t>::max())
    throw GlError("the GL mesh holds at most 2^32 vertices (lower --mesh-level)");
  // The plant's origin: its centre, rounded to float so that the shader's
  // (eye_hi − origin_hi) + eye_lo is the exact offset split in two.
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const glm::dvec3& p : part.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const glm::vec3 origin_hi(0.5 * (lo + hi));
  const glm::dvec3 origin(origin_hi);

  const uint32_t first_frustum = static_cast<uint32_t>(out.frusta.size());
  for (const Frustum& f : skinned.frusta)
    out.frusta.push_back({{origin_hi.x, origin_hi.y, origin_hi.z, 0.0f},
                          {plant | (f.material << gl::kPlantIndexBits), f.chain, f.segment, 0u}});

  // tessellate.h gives every frustum its own vertices (a joint's shared row is copied),
  // so a vertex's frustum is that of any triangle using it.
  std::vector<uint32_t> vertex_frustum(part.positions.size(), 0);
  for (size_t t = 0; t < part.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) vertex_frustum[part.indices[3 * t + c]] = part.triangle_frustum[t];

  const uint32_t first_vertex = static_cast<uint32_t>(out.vertices.size());
  out.vertices.reserve(out.vertices.size() + part.positions.size());
  for (size_t v = 0; v < part.positions.size(); ++v) {
    const glm::vec3 p(part.positions[v] - origin), n(part.normals[v]);
    out.vertices.push_back({{p.x, p.y, p.z},
                            {n.x, n.y, n.z},
                            {static_cast<float>(part.uvs[v].x), static_cast<float>(part.uvs[v].y)},
                            first_frustum + vertex_frustum[v]});
  }
  out.indices.reserve(out.indices.size() + part.indices.size());
  for (uint32_t i : part.indices) out.indices.push_back(first_vertex + i);

  // A sphere around each frustum's vertices (its triangles lie in their hull).
  const size_t count = skinned.frusta.size();
  std::vector<glm::dvec3> f_lo(count, glm::dvec3(std::numeric_limits<double>::infinity())),
      f_hi(count, glm::dvec3(-std::numeric_limits<double>::infinity()));
  for (size_t v = 0; v < part.positions.size(); ++v) {
    const uint32_t f = vertex_frustum[v];
    f_lo[f] = glm::min(f_lo[f], part.positions[v]);
    f_hi[f] = glm::max(f_hi[f], part.positions[v]);
  }
  std::vector<double> radius(count, 0.0);
  for (size_t v = 0; v < part.positions.size(); ++v) {
    const uint32_t f = vertex_frustum[v];
    radius[f] = std::max(radius[f], glm::length(part.positions[v] - 0.5 * (f_lo[f] + f_hi[f])));
  }
  for (size_t f = 0; f < count; ++f) {
    if (!(f_lo[f].x <= f_hi[f].x)) continue;  // no vertex
    // Grown far above float rounding of the uploaded positions (~1e-7 of the plant).
    const double pad = 1e-6 * (glm::length(hi - lo) + radius[f]);
    spheres->push_back({0.5 * (f_lo[f] + f_hi[f]), radius[f] * 1.001 + pad});
  }
}

// Appends plant `plant`'s leaves `part` (leaf_mesh.h: one plant's) to `out`: a record
// per leaf (ids plant | material << 24, kLeafChain, the leaf's index, its back material + 1
// when it has one of its own, else 0: mesh.frag.glsl's side_material), its flat normal at
// every vertex, its leaf_uvs, and a sphere per leaf to *spheres.
void append_leaves(MeshArrays& out, const LeafMesh& part, std::vector<GlMeshSphere>* spheres) {
  if (part.empty()) return;
  if (out.vertices.size() + part.positions.size() > std::numeric_limits<uint32_t>::max())
    throw GlError("the GL leaves hold at most 2^32 vertices");
  const Aabb box = part.bounds();
  const glm::vec3 origin_hi(0.5 * (box.lo + box.hi));
  const glm::dvec3 origin(origin_hi);
  const uint32_t first_record = static_cast<uint32_t>(out.frusta.size());
  for (const LeafRef& leaf : part.leaves)
    out.frusta.push_back({{origin_hi.x, origin_hi.y, origin_hi.z, 0.0f},
                          {leaf.plant | (std::min(leaf.material, 255u) << gl::kPlantIndexBits), gl::kLeafChain,
                           leaf.leaf, leaf.back_material != leaf.material ? std::min(leaf.back_material, 255u) + 1 : 0u}});
  const std::vector<uint32_t>& vertex_leaf = part.vertex_leaf;
  const uint32_t first_vertex = static_cast<uint32_t>(out.vertices.size());
  for (size_t v = 0; v < part.positions.size(); ++v) {
    const glm::vec3 q(part.positions[v] - origin), n(part.leaves[vertex_leaf[v]].normal);
    const glm::vec2 uv(part.uvs[v]);
    out.vertices.push_back({{q.x, q.y, q.z}, {n.x, n.y, n.z}, {uv.x, uv.y}, first_record + vertex_leaf[v]});
  }
  for (uint32_t i : part.indices) out.indices.push_back(first_vertex + i);
  std::vector<Aabb> boxes(part.leaves.size(), empty_box());
  for (size_t v = 0; v < part.positions.size(); ++v) grow(boxes[vertex_leaf[v]], part.positions[v]);
  for (const Aabb& b : boxes) {
    const double radius = 0.5 * glm::length(b.hi - b.lo);
    spheres->push_back({0.5 * (b.lo + b.hi), radius * 1.001 + 1e-6 * (glm::length(box.hi - box.lo) + radius)});
  }
}

}  // namespace

GlMeshSphere enclosing_sphere(const std::vector<GlMeshSphere>& spheres) {
  if (spheres.empty()) return {};
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const GlMeshSphere& s : spheres) lo = glm::min(lo, s.centre - s.radius), hi = glm::max(hi, s.centre + s.radius);
  const glm::dvec3 centre = 0.5 * (lo + hi);
  double radius = 0;
  for (const GlMeshSphere& s : spheres) radius = std::max(radius, glm::length(s.centre - centre) + s.radius);
  return {centre, radius * (1 + 1e-9)};
}

namespace {

bool sun_shines(const Scene& scene) {
  return scene.sun.radiance.x > 0 || scene.sun.radiance.y > 0 || scene.sun.radiance.z > 0;
}

}  // namespace

// One draw of the instanced mesh (INSTANCED): a skeleton's triangles once per plant of it.
struct MeshDraw {
  uint32_t first_index = 0, indices = 0;
  uint32_t first_instance = 0, instances = 0;
};

struct GlMesh::State {
  RenderOptions options;
  bool leaves = false;  // leaves_of: the scene's leaves instead of its tessellated frusta
  bool fillets = false;  // fillets_of: the crotches' fillets instead of the tessellated frusta
  std::vector<RenderPass> setup_passes;
  std::vector<GlMeshSphere> spheres;
  uint64_t triangles = 0, drawn_triangles = 0, frusta = 0, gpu_bytes = 0;
  bool displaced = false;
  int bark_texture_units = 0;  // > 0: the G-buffer program writes the bark albedo
  std::optional<std::vector<HeightFn>> displacements;  // per plant (GS+R), read once, kept for update
  GlVertexArray vao;
  GlBuffer vertex_buffer, index_buffer, frustum_buffer, instance_buffer;
  // Instancing (gl_instances.h): the plants in the world first under the identity, then one
  // draw per shared skeleton; empty: one plain draw of every triangle.
  std::vector<MeshDraw> draws;
  std::vector<GpuInstance> instances;
  size_t instanced_plants = 0, skeletons = 0;
  GlProgramObject programs[2][2];  // [shadow][instanced]
  std::shared_ptr<const LeafImages> leaf_images;  // leaves_of only: the table's (null: plain leaves)
  GlTexture leaf_texture;                         // its layers as one 2D array (LEAF_IMAGES)

  // The GS+R displacement of each plant (height_maps.h), read on the first build and
  // kept for update; null when no plant is displaced.
  const std::vector<HeightFn>* plant_displacements(const Scene& scene) {
    const bool any_height = std::any_of(scene.plants.begin(), scene.plants.end(), [](const ScenePlant& p) {
      return p.bark.height_texture.has_value() && p.bark.relief_depth_m > 0;
    });
    if (!options.geometry.displace || !any_height) return nullptr;
    if (!displacements) {
      Expected<std::vector<HeightFn>> read = scene_displacements(scene);
      if (!read) throw std::runtime_error(read.error().message);
      displacements = std::move(*read);
    }
    return &*displacements;
  }

  // Appends the shared skeletons of `split` (after the world's plants, already in `arrays`):
  // `append(group, spheres)` adds the geometry of the group's first plant in its skeleton's
  // frame; one draw per group, one instance and one sphere per plant (around the skeleton's
  // spheres, through the plant's transform).
  template <typename Append>
  void append_instanced(const Scene& scene, const GlInstanceGroups& split, MeshArrays& arrays,
                        std::vector<GlMeshSphere>& world_spheres, const Append& append) {
    draws.clear();
    instances.clear();
    instanced_plants = 0;
    skeletons = 0;
    drawn_triangles = arrays.indices.size() / 3;
    if (!split.instanced()) return;
    const uint32_t world_indices = static_cast<uint32_t>(arrays.indices.size());
    if (world_indices > 0) {
      draws.push_back({0, world_indices, 0, 1});
      instances.push_back(gpu_instance(PlantTransform{}, 0, true));
    }
    for (const std::vector<uint32_t>& group : split.groups) {
      const uint32_t first = static_cast<uint32_t>(arrays.indices.size());
      std::vector<GlMeshSphere> local;
      append(group, &local);
      const uint32_t count = static_cast<uint32_t>(arrays.indices.size()) - first;
      if (count == 0) continue;
      const GlMeshSphere bound = enclosing_sphere(local);
      draws.push_back({first, count, static_cast<uint32_t>(instances.size()), static_cast<uint32_t>(group.size())});
      for (uint32_t p : group) {
        const PlantTransform t = PlantTransform::of(scene.plants[p]);
        instances.push_back(gpu_instance(t, p, false));
        world_spheres.push_back({t.to_world(bound.centre), bound.radius * t.scale * (1 + 1e-6)});
      }
      instanced_plants += group.size();
      ++skeletons;
      drawn_triangles += uint64_t{count / 3} * group.size();
    }
    if (draws.size() == 1 && instances.front().own) draws.clear();  // nothing shared after all
    if (draws.empty()) instances.clear();
  }

  // Tessellates, displaces and uploads every plant; replaces the passes' record with what
  // this did. Returns the bytes uploaded.
  uint64_t build(const Scene& scene) {
    setup_passes.clear();
    if (scene.plants.size() >= gl::kMaxPlants) throw GlError("the GL backend draws at most 2^24 plants");
    for (const ScenePlant& plant : scene.plants)
      if (!plant.skeleton) throw std::logic_error("GlMesh: a plant has no skeleton (call grow_scene_plants)");
    MeshArrays arrays;
    if (leaves) return build_leaves(scene, arrays);
    const GeometryOptions& geometry = options.geometry;
    TessellateOptions tessellation;
    tessellation.level = geometry.mesh_level;
    const std::vector<HeightFn>* heights = plant_displacements(scene);
    // Drawn through a transform: not displaced (the relief's depth is in world metres) and,
    // with a skin twist (per world metre), at scale 1 — the frusta's rule (render_gl.cpp).
    const GlInstanceGroups split = gl_instance_groups(scene, geometry.instance, [&](uint32_t p) {
      const ScenePlant& plant = scene.plants[p];
      if (options.skin.twist_rad_per_m != 0 && plant.scale != 1) return false;
      return !(heights && (*heights)[p]);
    });
    double skin_s = 0, tessellate_s = 0, displace_s = 0;
    uint64_t skinned_frusta = 0, placed_frusta = 0;
    std::vector<GlMeshSphere> world_spheres;
    // The crotches whose fillets a plant needs (crotch.h crotch_seen): with culling on, the
    // renderer draws the scene's camera (the CLI, the benchmarks; the studio, whose camera
    // moves, turns it off), so only those at least kFilletMinPixels wide there, as on the
    // CPU. `eyes`: the camera's eye in the skeleton's frame (a placed plant's: the world's;
    // an instanced skeleton's: one per instance, which share the fillets any of them needs).
    const double view_pixels_per_radian = pixels_per_radian(scene);
    size_t crotches_found = 0, crotches_meshed = 0;
    const auto seen = [&](std::vector<Crotch> crotches, std::span<const glm::dvec3> eyes) {
      crotches_found += crotches.size();
      if (geometry.cull) crotches = crotches_seen(std::move(crotches), eyes, view_pixels_per_radian);
      crotches_meshed += crotches.size();
      return crotches;
    };
    // Plant p's skeleton (placed in the world, or in its own frame) tessellated into arrays.
    const auto append = [&](uint32_t p, const Skeleton& skeleton, std::span<const glm::dvec3> eyes,
                            std::vector<GlMeshSphere>* out) -> size_t {
      const ScenePlant& plant = scene.plants[p];
      Clock::time_point start = Clock::now();
      const SkinOptions skin = options.skin.styled(plant.skin);
      const SkinnedSkeleton skinned = skin_skeleton(skeleton, skin);
      skinned_frusta += skinned.frusta.size();
      skin_s += seconds_since(start);
      TriangleMesh part;
      if (fillets) {
        start = Clock::now();
        if (skin.blend_crotches)
          part = crotch_fillets(seen(find_crotches(skeleton, skinned.frusta), eyes), skeleton, skinned.frusta);
        tessellate_s += seconds_since(start);
      } else {
        // build_scene_geometry's mesh path: the same plant_mesh, within the same limit,
        // and the same fillets.
        check_mesh_fits(tessellation_size(skinned.frusta.size(), tessellation),
                        arrays.vertices.size() * sizeof(MeshVertex) + arrays.indices.size() * sizeof(uint32_t));
        const HeightFn height = heights ? (*heights)[p] : HeightFn{};
        const std::vector<Crotch> crotches =
            skin.blend_crotches ? find_crotches(skeleton, skinned.frusta) : std::vector<Crotch>{};
        part = plant_mesh(skinned, tessellation, height, plant.bark.relief_depth_m,
                          geometry.relief_options.max_depth_per_radius, &tessellate_s, &displace_s,
                          height ? std::span<const Crotch>(crotches) : std::span<const Crotch>{});
        if (skin.blend_crotches) append_mesh(part, crotch_fillets(seen(crotches, eyes), skeleton, skinned.frusta), 0);
        if (height) ++arrays.displaced_plants;
      }
      start = Clock::now();
      append_plant(arrays, part, skinned, p, out);
      tessellate_s += seconds_since(start);
      return skinned.frusta.size();
    };
    const glm::dvec3 world_eye = scene.camera.eye;
    for (uint32_t p : split.world)
      placed_frusta += append(p, place_plant(scene.plants[p]), {&world_eye, 1}, &world_spheres);
    append_instanced(scene, split, arrays, world_spheres,
                     [&](const std::vector<uint32_t>& group, std::vector<GlMeshSphere>* local) {
                       const uint32_t p = group.front();
                       std::vector<glm::dvec3> eyes;
                       eyes.reserve(group.size());
                       for (uint32_t q : group) eyes.push_back(PlantTransform::of(scene.plants[q]).to_local(world_eye));
                       placed_frusta += append(p, *scene.plants[p].skeleton, eyes, local) * group.size();
                     });
    if (arrays.indices.size() > static_cast<size_t>(INT_MAX))
      throw GlError("the GL mesh draws at most 2^31 indices in one call (lower --mesh-level)");
    triangles = arrays.indices.size() / 3;
    frusta = placed_frusta;
    displaced = arrays.displaced_plants > 0;
    spheres = std::move(world_spheres);
    std::string skin_detail = std::to_string(scene.plants.size()) + " plants, " + std::to_string(frusta) + " frusta";
    if (!draws.empty())
      skin_detail += "; " + std::to_string(instanced_plants) + " plants as instances of " + std::to_string(skeletons) +
                     " skeletons, " + std::to_string(skinned_frusta) + " frusta skinned";
    setup_passes.push_back({"skin", skin_s, skin_detail});
    setup_passes.push_back({"tessellate", tessellate_s,
                            std::to_string(triangles) + " triangles, GS " + std::to_string(geometry.mesh_level) + ", " +
                                std::to_string(arrays.vertices.size()) + " vertices" + drawn_detail() +
                                fillet_detail(crotches_meshed, crotches_found)});
    if (displaced)
      setup_passes.push_back({"displace", displace_s,
                              std::to_string(arrays.displaced_plants) + " plants by their height maps"});
    if (arrays.indices.empty()) {  // fillets_of with no crotch: nothing to upload or draw
      gpu_bytes = 0;
      return 0;
    }
    return upload(arrays);
  }

  // ", N of M crotches' fillets (the rest under 2 px)" when a view left some out.
  static std::string fillet_detail(size_t meshed, size_t found) {
    if (meshed == found) return {};
    return ", " + std::to_string(meshed) + " of " + std::to_string(found) + " crotches' fillets (the rest under " +
           std::to_string(static_cast<int>(kFilletMinPixels)) + " px)";
  }

  // ", N drawn" when instances draw more triangles than were uploaded.
  std::string drawn_detail() const {
    return draws.empty() ? std::string() : " (" + std::to_string(drawn_triangles) + " triangles drawn)";
  }

  // The leaves of every plant (placed as the frusta are, or in their skeleton's frame for
  // the plants that share one: leaves depend on nothing of where a plant stands), uploaded.
  uint64_t build_leaves(const Scene& scene, MeshArrays& arrays) {
    const Clock::time_point start = Clock::now();
    const GlInstanceGroups split = gl_instance_groups(
        scene, options.geometry.instance, [&](uint32_t p) { return !scene.plants[p].skeleton->leaves.empty(); });
    uint64_t uploaded = 0, drawn = 0;
    std::vector<GlMeshSphere> world_spheres;
    for (uint32_t p : split.world) {
      if (scene.plants[p].skeleton->leaves.empty()) continue;
      LeafMesh part;
      sylva::append_leaves(part, place_plant(scene.plants[p]), p);
      uploaded += part.leaves.size();
      drawn += part.leaves.size();
      append_leaves(arrays, part, &world_spheres);
    }
    append_instanced(scene, split, arrays, world_spheres,
                     [&](const std::vector<uint32_t>& group, std::vector<GlMeshSphere>* local) {
                       LeafMesh part;
                       sylva::append_leaves(part, *scene.plants[group.front()].skeleton, group.front());
                       uploaded += part.leaves.size();
                       drawn += part.leaves.size() * group.size();
                       append_leaves(arrays, part, local);
                     });
    triangles = arrays.indices.size() / 3;
    frusta = 0;
    displaced = false;
    spheres = std::move(world_spheres);
    std::string detail = std::to_string(drawn) + " leaves, " + std::to_string(drawn_triangles) + " triangles";
    if (!draws.empty())
      detail += "; " + std::to_string(instanced_plants) + " plants as instances of " + std::to_string(skeletons) +
                " skeletons, " + std::to_string(uploaded) + " leaves and " + std::to_string(triangles) +
                " triangles uploaded";
    setup_passes.push_back({"triangulate", seconds_since(start), detail});
    return upload(arrays);
  }

  // The leaf images' layers as one RGBA8 2D array texture (leaf_images.h: GL_LINEAR,
  // clamped, no MIP levels, as LeafImages::sample reads them); returns its bytes.
  uint64_t upload_leaf_images() {
    const LeafImages& images = *leaf_images;
    const GLsizei layers = static_cast<GLsizei>(std::max<size_t>(images.layer_count(), 1));
    const GLsizei w = static_cast<GLsizei>(std::max(images.width(), 1u)), h = static_cast<GLsizei>(std::max(images.height(), 1u));
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
    leaf_texture = GlTexture(id);
    glTextureStorage3D(id, 1, GL_RGBA8, w, h, layers);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (size_t k = 0; k < images.layer_count(); ++k)
      glTextureSubImage3D(id, 0, 0, 0, static_cast<GLint>(k), w, h, 1, GL_RGBA, GL_UNSIGNED_BYTE, images.layer(k).data());
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    check_gl("GL leaf images upload");
    return uint64_t{static_cast<uint64_t>(w) * static_cast<uint64_t>(h) * 4 * static_cast<uint64_t>(layers)};
  }

  // mesh.frag.glsl's LEAF_IMAGES uniforms: each material's layer and flags, and the texture.
  void bind_leaf_images(GLuint program_id) const {
    GLint layer[gl::kMaxMaterials];
    GLuint flags[gl::kMaxMaterials];
    for (uint32_t m = 0; m < gl::kMaxMaterials; ++m) {
      layer[m] = leaf_images->layer_of(m);
      flags[m] = (leaf_images->has_albedo(m) ? 1u : 0u) | (leaf_images->has_cutout(m) ? 2u : 0u) |
                 (leaf_images->one_sided(m) ? 4u : 0u);
    }
    glProgramUniform1iv(program_id, glGetUniformLocation(program_id, "u_leaf_layer"), gl::kMaxMaterials, layer);
    glProgramUniform1uiv(program_id, glGetUniformLocation(program_id, "u_leaf_flags"), gl::kMaxMaterials, flags);
    glBindTextureUnit(gl::kLeafImagesUnit, leaf_texture.id());
  }

  // Uploads `arrays` (replacing what was there) and records the "upload" pass.
  uint64_t upload(const MeshArrays& arrays) {
    const size_t vertex_bytes = arrays.vertices.size() * sizeof(MeshVertex);
    const size_t index_bytes = arrays.indices.size() * sizeof(uint32_t);
    const size_t frustum_bytes = arrays.frusta.size() * sizeof(MeshFrustumRecord);
    const Clock::time_point start = Clock::now();
    vertex_buffer.reset();
    index_buffer.reset();
    frustum_buffer.reset();
    instance_buffer.reset();
    vertex_buffer = make_gl_buffer(arrays.vertices.data(), vertex_bytes);
    const size_t instance_bytes = instances.size() * sizeof(GpuInstance);
    if (!instances.empty()) instance_buffer = make_gl_buffer(instances.data(), instance_bytes);
    index_buffer = make_gl_buffer(arrays.indices.data(), index_bytes);
    frustum_buffer = make_gl_buffer(arrays.frusta.data(), frustum_bytes);
    if (!vao) vao = make_gl_vertex_array();
    glVertexArrayVertexBuffer(vao.id(), 0, vertex_buffer.id(), 0, sizeof(MeshVertex));
    glVertexArrayElementBuffer(vao.id(), index_buffer.id());
    glVertexArrayAttribFormat(vao.id(), 0, 3, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, position));
    glVertexArrayAttribFormat(vao.id(), 1, 3, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, normal));
    glVertexArrayAttribFormat(vao.id(), 2, 2, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, uv));
    glVertexArrayAttribIFormat(vao.id(), 3, 1, GL_UNSIGNED_INT, offsetof(MeshVertex, frustum));
    for (GLuint a = 0; a < 4; ++a) {
      glVertexArrayAttribBinding(vao.id(), a, 0);
      glEnableVertexArrayAttrib(vao.id(), a);
    }
    check_gl("GL mesh upload");
    gpu_bytes = vertex_bytes + index_bytes + frustum_bytes + instance_bytes;
    setup_passes.push_back({"upload", seconds_since(start),
                            std::to_string(gpu_bytes / 1024) + " KiB: " + std::to_string(arrays.vertices.size()) +
                                " vertices (36 B) + " + std::to_string(triangles) + " triangles (12 B) + " +
                                std::to_string(arrays.frusta.size()) + (leaves ? " leaf" : " frustum") +
                                " records (32 B)" +
                                (instances.empty() ? std::string()
                                                   : " + " + std::to_string(instances.size()) + " instances (48 B)")});
    return gpu_bytes;
  }

  ShaderProgramSource variant(MeshPass pass) const {
    return mesh_program(pass, pass == MeshPass::shadow ? 0 : bark_texture_units, leaf_images != nullptr, !draws.empty());
  }

  // The pass's program for the current draws (plain or INSTANCED), built on first use.
  GLuint program(MeshPass pass, double* compile_s) {
    GlProgramObject& program = programs[pass == MeshPass::shadow ? 1 : 0][draws.empty() ? 0 : 1];
    if (program) return program.id();
    const Clock::time_point start = Clock::now();
    program = GlProgramObject(build_gl_program(variant(pass)).id);
    if (compile_s) *compile_s += seconds_since(start);
    return program.id();
  }

  // Draws every triangle with `program` (its uniforms set), both faces: one draw, or
  // (instanced) one instanced draw per skeleton, u_instance_base its first instance. The
  // caller's instance buffer (the frusta's, at the same binding) is bound back after.
  void draw(GLuint program_id) {
    if (triangles == 0) return;
    GLint previous_vao = 0, previous_instances = 0;
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &previous_vao);
    const GLboolean cull = glIsEnabled(GL_CULL_FACE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(vao.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kMeshFrustaBinding, frustum_buffer.id());
    glUseProgram(program_id);
    if (leaf_images) bind_leaf_images(program_id);
    if (draws.empty()) {
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * triangles), GL_UNSIGNED_INT, nullptr);
    } else {
      glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, gl::kInstancesBinding, &previous_instances);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kInstancesBinding, instance_buffer.id());
      for (const MeshDraw& d : draws) {
        set_uniform_uint(program_id, "u_instance_base", d.first_instance);
        glDrawElementsInstanced(GL_TRIANGLES, static_cast<GLsizei>(d.indices), GL_UNSIGNED_INT,
                                reinterpret_cast<const void*>(uintptr_t{d.first_index} * sizeof(uint32_t)),
                                static_cast<GLsizei>(d.instances));
      }
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kInstancesBinding, static_cast<GLuint>(previous_instances));
    }
    glBindVertexArray(static_cast<GLuint>(previous_vao));
    if (cull) glEnable(GL_CULL_FACE);
  }
};

GlMesh::GlMesh(const Scene& scene, const RenderOptions& options, int bark_texture_units)
    : state_(std::make_unique<State>()) {
  state_->options = options;
  state_->bark_texture_units = std::max(0, bark_texture_units);
  finish_construction(scene);
}

GlMesh::GlMesh(const Scene& scene, const RenderOptions& options, int bark_texture_units, FilletsTag)
    : state_(std::make_unique<State>()) {
  state_->options = options;
  state_->bark_texture_units = std::max(0, bark_texture_units);
  state_->fillets = true;
  finish_construction(scene);
}

std::unique_ptr<GlMesh> GlMesh::fillets_of(const Scene& scene, const RenderOptions& options, int bark_texture_units) {
  const bool any = std::any_of(scene.plants.begin(), scene.plants.end(), [&](const ScenePlant& p) {
    return p.skeleton && options.skin.styled(p.skin).blend_crotches;
  });
  if (!any) return nullptr;
  auto mesh = std::unique_ptr<GlMesh>(new GlMesh(scene, options, bark_texture_units, FilletsTag{}));
  if (mesh->triangles() == 0) return nullptr;
  return mesh;
}

void GlMesh::finish_construction(const Scene& scene) {
  State& st = *state_;
  st.build(scene);
  double compile_s = 0;
  std::string names = st.variant(MeshPass::gbuffer).name;
  st.program(MeshPass::gbuffer, &compile_s);
  if (sun_shines(scene)) {
    st.program(MeshPass::shadow, &compile_s);
    names += ", " + st.variant(MeshPass::shadow).name;
  }
  st.setup_passes.push_back({"programs", compile_s, names});
  check_gl("GL mesh programs");
}

GlMesh::GlMesh(const Scene& scene, const RenderOptions& options, std::shared_ptr<const LeafImages> images, LeavesTag)
    : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.options = options;
  st.leaves = true;
  st.leaf_images = std::move(images);
  st.build(scene);
  if (st.leaf_images) st.gpu_bytes += st.upload_leaf_images();
  double compile_s = 0;
  st.program(MeshPass::gbuffer, &compile_s);
  if (sun_shines(scene)) st.program(MeshPass::shadow, &compile_s);
  check_gl("GL leaves programs");
}

std::unique_ptr<GlMesh> GlMesh::leaves_of(const Scene& scene, const RenderOptions& options,
                                          std::shared_ptr<const LeafImages> images) {
  const bool any = std::any_of(scene.plants.begin(), scene.plants.end(),
                               [](const ScenePlant& p) { return p.skeleton && !p.skeleton->leaves.empty(); });
  if (!any) return nullptr;
  return std::unique_ptr<GlMesh>(new GlMesh(scene, options, std::move(images), LeavesTag{}));
}

GlMesh::~GlMesh() = default;

uint64_t GlMesh::update(const Scene& scene) { return state_->build(scene); }

void GlMesh::draw_gbuffer(const GlCameraView& camera, double footprint_scale) {
  State& st = *state_;
  if (st.triangles == 0) return;
  const GLuint p = st.program(MeshPass::gbuffer, nullptr);
  set_camera_uniforms(p, camera);
  if (st.bark_texture_units > 0) set_uniform(p, "u_footprint_scale", footprint_scale);
  st.draw(p);
  check_gl("GL mesh G-buffer pass");
}

void GlMesh::draw_shadow(const GlSunView& view) {
  State& st = *state_;
  if (st.triangles == 0) return;
  const GLuint p = st.program(MeshPass::shadow, nullptr);
  set_sun_view_uniforms(p, view);
  st.draw(p);
  check_gl("GL mesh shadow pass");
}

uint64_t GlMesh::triangles() const { return state_->triangles; }
uint64_t GlMesh::frusta() const { return state_->frusta; }
uint64_t GlMesh::gpu_bytes() const { return state_->gpu_bytes; }
int GlMesh::level() const { return state_->options.geometry.mesh_level; }
bool GlMesh::displaced() const { return state_->displaced; }
std::string GlMesh::label() const { return std::string(displaced() ? "GS+R " : "GS ") + std::to_string(level()); }
std::string GlMesh::gbuffer_variant() const { return state_->variant(MeshPass::gbuffer).name; }
std::string GlMesh::shadow_variant() const { return state_->variant(MeshPass::shadow).name; }
uint64_t GlMesh::drawn_triangles() const { return state_->drawn_triangles; }
size_t GlMesh::instanced_plants() const { return state_->instanced_plants; }
const std::vector<GlMeshSphere>& GlMesh::bounding_spheres() const { return state_->spheres; }
const std::vector<RenderPass>& GlMesh::setup_passes() const { return state_->setup_passes; }

}  // namespace sylva
