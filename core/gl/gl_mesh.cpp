// gl_mesh.cpp — the polygon baseline on the GPU (paper 000 sec. 4: the GS and GS+R
// columns the ray caster is raced against): the CPU mesh path's triangles (tessellate.h,
// displace), uploaded once and rasterised into the ray caster's G-buffer. See gl_mesh.h.
#include "core/gl/gl_mesh.h"

#include <algorithm>
#include <climits>
#include <cstddef>
#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>

#include "core/gl/gl_api.h"
#include "core/gl/gl_program.h"
#include "core/render_common.h"
#include "core/cpu/texture.h"
#include "core/plant_mesh.h"

namespace sylva {

namespace {

using render_common::Clock;
using render_common::seconds_since;

// One vertex as mesh.vert.glsl reads it (attributes 0–3).
struct MeshVertex {
  float position[3];  // metres, relative to the plant's origin_hi
  float normal[3];    // unit shading normal
  float uv[2];        // u turns, v_m metres
  uint32_t frustum;   // index into the frustum records
};
static_assert(sizeof(MeshVertex) == 36);

// One frustum as mesh.vert.glsl's MeshFrustum (std430: vec4, uvec4).
struct MeshFrustumRecord {
  float origin_hi[4];  // the plant's origin, float-exact; w unused
  uint32_t ids[4];     // plant | material << 24, chain, segment, 0
};
static_assert(sizeof(MeshFrustumRecord) == 32);

constexpr GLuint kMeshFrustaBinding = 7;  // mesh.vert.glsl
constexpr uint32_t kMaxPlants = 1u << 24;  // plant bits of the G-buffer's ids

// What is uploaded, built on the CPU.
struct MeshArrays {
  std::vector<MeshVertex> vertices;
  std::vector<uint32_t> indices;
  std::vector<MeshFrustumRecord> frusta;
  std::vector<GlMeshSphere> spheres;
  uint32_t displaced_plants = 0;
};

// Appends plant `plant`'s mesh `part` (tessellated from `skinned`) to `out`.
void append_plant(MeshArrays& out, const TriangleMesh& part, const SkinnedSkeleton& skinned, uint32_t plant) {
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
    out.frusta.push_back({{origin_hi.x, origin_hi.y, origin_hi.z, 0.0f}, {plant | (f.material << 24), f.chain, f.segment, 0u}});

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
    out.spheres.push_back({0.5 * (f_lo[f] + f_hi[f]), radius[f] * 1.001 + pad});
  }
}

GLuint make_buffer(const void* data, size_t bytes) {
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  // Zero-sized storage is an error: an empty mesh gets one unused 64-byte element.
  const uint8_t placeholder[64] = {};
  glNamedBufferStorage(buffer, bytes ? static_cast<GLsizeiptr>(bytes) : 64, bytes ? data : placeholder, 0);
  return buffer;
}

void check_gl(const char* where) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) throw GlError(std::string("GL mesh, ") + where + ": GL error " + std::to_string(error));
}

GLint location(GLuint program, const char* name) { return glGetUniformLocation(program, name); }
void set_vec3(GLuint p, const char* name, const glm::vec3& v) { glProgramUniform3f(p, location(p, name), v.x, v.y, v.z); }
void set_vec2(GLuint p, const char* name, double a, double b) {
  glProgramUniform2f(p, location(p, name), static_cast<float>(a), static_cast<float>(b));
}

bool sun_shines(const Scene& scene) {
  return scene.sun.radiance.x > 0 || scene.sun.radiance.y > 0 || scene.sun.radiance.z > 0;
}

}  // namespace

struct GlMesh::State {
  RenderOptions options;
  std::vector<RenderPass> setup_passes;
  std::vector<GlMeshSphere> spheres;
  uint64_t triangles = 0, frusta = 0, gpu_bytes = 0;
  bool displaced = false;
  int bark_texture_units = 0;  // > 0: the G-buffer program writes the bark albedo
  std::unique_ptr<SceneTextures> own_textures;  // height maps opened here, kept for update
  GLuint vao = 0, vertex_buffer = 0, index_buffer = 0, frustum_buffer = 0;
  GLuint gbuffer_program = 0, shadow_program = 0;

  ~State() {
    release_buffers();
    glDeleteVertexArrays(1, &vao);
    if (gbuffer_program) glDeleteProgram(gbuffer_program);
    if (shadow_program) glDeleteProgram(shadow_program);
  }

  void release_buffers() {
    const GLuint buffers[3] = {vertex_buffer, index_buffer, frustum_buffer};
    glDeleteBuffers(3, buffers);
    vertex_buffer = index_buffer = frustum_buffer = 0;
  }

  // Tessellates, displaces and uploads every plant; replaces the passes' record with what
  // this did. Returns the bytes uploaded.
  uint64_t build(const Scene& scene, const SceneTextures* textures) {
    setup_passes.clear();
    if (scene.plants.size() >= kMaxPlants) throw GlError("the GL backend draws at most 2^24 plants");
    const GeometryOptions& geometry = options.geometry;
    TessellateOptions tessellation;
    tessellation.level = geometry.mesh_level;
    // Height maps for GS+R: the caller's, else opened here once (update reuses them).
    const bool any_height = std::any_of(scene.plants.begin(), scene.plants.end(), [](const ScenePlant& p) {
      return p.bark.height_texture.has_value() && p.bark.relief_depth_m > 0;
    });
    if (geometry.displace && any_height && !textures) {
      if (!own_textures) {
        SceneTextures::OpenResult opened = SceneTextures::open(scene);
        if (opened.error) throw std::runtime_error(*opened.error);
        own_textures = std::move(opened.textures);
      }
      textures = own_textures.get();
    }

    MeshArrays arrays;
    double skin_s = 0, tessellate_s = 0, displace_s = 0;
    uint64_t skinned_frusta = 0;
    for (uint32_t p = 0; p < scene.plants.size(); ++p) {
      const ScenePlant& plant = scene.plants[p];
      if (!plant.skeleton) throw std::logic_error("GlMesh: a plant has no skeleton (call grow_scene_plants)");
      Clock::time_point start = Clock::now();
      const SkinnedSkeleton skinned = skin_skeleton(place_plant(plant), options.skin);
      skinned_frusta += skinned.frusta.size();
      skin_s += seconds_since(start);
      // build_scene_geometry's mesh path: the same plant_mesh.
      const HeightFn height = geometry.displace && textures ? height_function_for(*textures, p) : HeightFn{};
      const TriangleMesh part = plant_mesh(skinned, tessellation, height, plant.bark.relief_depth_m,
                                           geometry.relief_options.max_depth_per_radius, &tessellate_s, &displace_s);
      if (height) ++arrays.displaced_plants;
      start = Clock::now();
      append_plant(arrays, part, skinned, p);
      tessellate_s += seconds_since(start);
    }
    if (arrays.indices.size() > static_cast<size_t>(INT_MAX))
      throw GlError("the GL mesh draws at most 2^31 indices in one call (lower --mesh-level)");
    triangles = arrays.indices.size() / 3;
    frusta = skinned_frusta;
    displaced = arrays.displaced_plants > 0;
    spheres = std::move(arrays.spheres);
    const size_t vertex_bytes = arrays.vertices.size() * sizeof(MeshVertex);
    const size_t index_bytes = arrays.indices.size() * sizeof(uint32_t);
    const size_t frustum_bytes = arrays.frusta.size() * sizeof(MeshFrustumRecord);
    setup_passes.push_back({"skin", skin_s,
                            std::to_string(scene.plants.size()) + " plants, " + std::to_string(frusta) + " frusta"});
    setup_passes.push_back({"tessellate", tessellate_s,
                            std::to_string(triangles) + " triangles, GS " + std::to_string(geometry.mesh_level) + ", " +
                                std::to_string(arrays.vertices.size()) + " vertices"});
    if (displaced)
      setup_passes.push_back({"displace", displace_s,
                              std::to_string(arrays.displaced_plants) + " plants by their height maps"});

    const Clock::time_point start = Clock::now();
    release_buffers();
    vertex_buffer = make_buffer(arrays.vertices.data(), vertex_bytes);
    index_buffer = make_buffer(arrays.indices.data(), index_bytes);
    frustum_buffer = make_buffer(arrays.frusta.data(), frustum_bytes);
    if (!vao) glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, vertex_buffer, 0, sizeof(MeshVertex));
    glVertexArrayElementBuffer(vao, index_buffer);
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, position));
    glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, normal));
    glVertexArrayAttribFormat(vao, 2, 2, GL_FLOAT, GL_FALSE, offsetof(MeshVertex, uv));
    glVertexArrayAttribIFormat(vao, 3, 1, GL_UNSIGNED_INT, offsetof(MeshVertex, frustum));
    for (GLuint a = 0; a < 4; ++a) {
      glVertexArrayAttribBinding(vao, a, 0);
      glEnableVertexArrayAttrib(vao, a);
    }
    check_gl("upload");
    gpu_bytes = vertex_bytes + index_bytes + frustum_bytes;
    setup_passes.push_back({"upload", seconds_since(start),
                            std::to_string(gpu_bytes / 1024) + " KiB: " + std::to_string(arrays.vertices.size()) +
                                " vertices (36 B) + " + std::to_string(triangles) + " triangles (12 B) + " +
                                std::to_string(arrays.frusta.size()) + " frustum records (32 B)"});
    return gpu_bytes;
  }

  GLuint program(MeshPass pass, double* compile_s) {
    GLuint& id = pass == MeshPass::shadow ? shadow_program : gbuffer_program;
    if (id) return id;
    const Clock::time_point start = Clock::now();
    id = build_gl_program(mesh_program(pass, bark_texture_units)).id;
    if (compile_s) *compile_s += seconds_since(start);
    return id;
  }

  // Draws every triangle with `program` (its uniforms set), both faces.
  void draw(GLuint program_id) {
    if (triangles == 0) return;
    GLint previous_vao = 0;
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &previous_vao);
    const GLboolean cull = glIsEnabled(GL_CULL_FACE);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(vao);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMeshFrustaBinding, frustum_buffer);
    glUseProgram(program_id);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * triangles), GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(static_cast<GLuint>(previous_vao));
    if (cull) glEnable(GL_CULL_FACE);
  }
};

GlMesh::GlMesh(const Scene& scene, const RenderOptions& options, int bark_texture_units,
               const SceneTextures* textures)
    : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.options = options;
  st.bark_texture_units = std::max(0, bark_texture_units);
  st.build(scene, textures);
  double compile_s = 0;
  std::string names = mesh_program(MeshPass::gbuffer, st.bark_texture_units).name;
  st.program(MeshPass::gbuffer, &compile_s);
  if (sun_shines(scene)) {
    st.program(MeshPass::shadow, &compile_s);
    names += ", " + mesh_program(MeshPass::shadow).name;
  }
  st.setup_passes.push_back({"programs", compile_s, names});
  check_gl("programs");
}

GlMesh::~GlMesh() = default;

uint64_t GlMesh::update(const Scene& scene, const SceneTextures* textures) { return state_->build(scene, textures); }

void GlMesh::draw_gbuffer(const GlMeshCamera& c) {
  State& st = *state_;
  const GLuint p = st.program(MeshPass::gbuffer, nullptr);
  const glm::vec3 eye_hi(c.eye);
  set_vec3(p, "u_eye_hi", eye_hi);
  set_vec3(p, "u_eye_lo", glm::vec3(c.eye - glm::dvec3(eye_hi)));
  set_vec3(p, "u_right", glm::vec3(c.right));
  set_vec3(p, "u_up", glm::vec3(c.up));
  set_vec3(p, "u_forward", glm::vec3(c.forward));
  set_vec2(p, "u_half_size", c.half_width, c.half_height);
  set_vec2(p, "u_image_size", c.width, c.height);
  set_vec2(p, "u_jitter", c.jitter_x, c.jitter_y);
  glProgramUniform1f(p, location(p, "u_near"), static_cast<float>(c.near));
  if (st.bark_texture_units > 0)
    glProgramUniform1f(p, location(p, "u_footprint_scale"), static_cast<float>(c.footprint_scale));
  st.draw(p);
  check_gl("G-buffer pass");
}

void GlMesh::draw_shadow(const GlMeshSunView& v) {
  State& st = *state_;
  const GLuint p = st.program(MeshPass::shadow, nullptr);
  const glm::vec3 centre_hi(v.centre);
  set_vec3(p, "u_light_hi", centre_hi);
  set_vec3(p, "u_light_lo", glm::vec3(v.centre - glm::dvec3(centre_hi)));
  set_vec3(p, "u_light_e0", glm::vec3(v.e0));
  set_vec3(p, "u_light_e1", glm::vec3(v.e1));
  set_vec3(p, "u_light_dir", glm::vec3(v.direction));
  glProgramUniform4f(p, location(p, "u_light_rect"), static_cast<float>(v.x_min), static_cast<float>(v.y_min),
                     static_cast<float>(v.side), static_cast<float>(v.side));
  set_vec2(p, "u_light_depth", v.s_near, v.s_range);
  st.draw(p);
  check_gl("shadow pass");
}

uint64_t GlMesh::triangles() const { return state_->triangles; }
uint64_t GlMesh::frusta() const { return state_->frusta; }
uint64_t GlMesh::gpu_bytes() const { return state_->gpu_bytes; }
int GlMesh::level() const { return state_->options.geometry.mesh_level; }
bool GlMesh::displaced() const { return state_->displaced; }
std::string GlMesh::label() const { return std::string(displaced() ? "GS+R " : "GS ") + std::to_string(level()); }
std::string GlMesh::gbuffer_variant() const { return mesh_program(MeshPass::gbuffer, state_->bark_texture_units).name; }
const std::vector<GlMeshSphere>& GlMesh::bounding_spheres() const { return state_->spheres; }
const std::vector<RenderPass>& GlMesh::setup_passes() const { return state_->setup_passes; }

}  // namespace sylva
