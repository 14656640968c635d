// render_gl.cpp — the OpenGL ray caster (see render_gl.h for the frame and what differs
// from the CPU reference; the shaders are in shaders/).
#include "core/gl/render_gl.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <OpenImageIO/imageio.h>

#include <glm/geometric.hpp>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "core/gl/gl_api.h"
#include "core/gl/gl_mesh.h"
#include "core/gl/gl_program.h"
#include "core/materials.h"
#include "core/relief.h"
#include "core/render_common.h"
#include "core/util/math.h"

namespace sylva {

namespace {

using render_common::CameraFrame;
using render_common::camera_frame;
using render_common::Clock;
using render_common::seconds_since;
constexpr int kMaxMaterials = 16;         // u_material_albedo's size in shade.frag.glsl
constexpr uint32_t kMaxPlants = 1u << 24;  // plant index bits in the G-buffer
constexpr int kShadowTexelsMin = 1024;
constexpr int kShadowTexelsMax = 8192;
constexpr double kShadowNormalOffsetTexels = 2;  // receiver offset along its normal
constexpr double kShadowDepthBiasTexels = 0.5;   // and along the sun direction

// A double split into two floats whose sum is it to ~2^-48 relative: what the shaders add
// back in float (frusta_common.glsl).
struct SplitVec3 {
  glm::vec3 hi, lo;
};
SplitVec3 split(const glm::dvec3& v) {
  const glm::vec3 hi(v);
  return {hi, glm::vec3(v - glm::dvec3(hi))};
}

// The orthographic sun view of one pass (frusta_common.glsl's SHADOW_PASS uniforms).
struct ShadowFrame {
  glm::dvec3 direction;  // unit, toward the sun
  glm::dvec3 e0, e1;     // axis_frame(direction)
  glm::dvec3 centre;     // c
  double x_min = 0, y_min = 0, side = 1;  // square map, metres
  double s_near = 0, s_range = 1;         // s = −dot(p − c, direction)
  double texel_m = 0;
};

struct Sphere {
  glm::dvec3 centre;
  double radius;
};

// Sets a uniform by name (a no-op where the variant has no such uniform).
GLint location(GLuint program, const char* name) { return glGetUniformLocation(program, name); }
void set_uniform(GLuint p, const char* name, const glm::vec3& v) { glProgramUniform3f(p, location(p, name), v.x, v.y, v.z); }
void set_uniform(GLuint p, const char* name, const glm::dvec3& v) { set_uniform(p, name, glm::vec3(v)); }
void set_uniform(GLuint p, const char* name, double a, double b) {
  glProgramUniform2f(p, location(p, name), static_cast<float>(a), static_cast<float>(b));
}
void set_uniform(GLuint p, const char* name, double a, double b, double c, double d) {
  glProgramUniform4f(p, location(p, name), static_cast<float>(a), static_cast<float>(b), static_cast<float>(c),
                     static_cast<float>(d));
}
void set_uniform(GLuint p, const char* name, double a) { glProgramUniform1f(p, location(p, name), static_cast<float>(a)); }
void set_uniform_int(GLuint p, const char* name, int a) { glProgramUniform1i(p, location(p, name), a); }

void check_gl(const char* where) {
  const GLenum error = glGetError();
  if (error == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", error);
  const char* name = error == GL_OUT_OF_MEMORY ? "GL_OUT_OF_MEMORY"
                     : error == GL_INVALID_OPERATION ? "GL_INVALID_OPERATION"
                     : error == GL_INVALID_VALUE ? "GL_INVALID_VALUE"
                     : error == GL_INVALID_ENUM ? "GL_INVALID_ENUM"
                     : error == GL_INVALID_FRAMEBUFFER_OPERATION ? "GL_INVALID_FRAMEBUFFER_OPERATION"
                                                                 : code;
  throw GlError(std::string(where) + ": " + name);
}

// GPU time of one kind of pass, over every time it ran in a frame.
struct PassTimer {
  std::vector<GLuint> queries;
  void begin() {
    GLuint q = 0;
    glCreateQueries(GL_TIME_ELAPSED, 1, &q);
    glBeginQuery(GL_TIME_ELAPSED, q);
    queries.push_back(q);
  }
  static void end() { glEndQuery(GL_TIME_ELAPSED); }
  double seconds() {
    uint64_t total = 0;
    for (GLuint q : queries) {
      GLuint64 ns = 0;
      glGetQueryObjectui64v(q, GL_QUERY_RESULT, &ns);
      total += ns;
    }
    if (!queries.empty()) glDeleteQueries(static_cast<GLsizei>(queries.size()), queries.data());
    queries.clear();
    return total * 1e-9;
  }
};

// An immutable-storage buffer holding `bytes` of `data` (zero-sized storage is an error:
// an empty scene gets one unused 64-byte element).
GLuint make_buffer(const void* data, size_t bytes, GLbitfield flags = 0) {
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  std::vector<uint8_t> placeholder(64, 0);
  glNamedBufferStorage(buffer, bytes ? static_cast<GLsizeiptr>(bytes) : 64, bytes ? data : placeholder.data(), flags);
  return buffer;
}

constexpr size_t kMaxBarkImages = 16;  // texture units for u_bark_textures (GL 4.5: >= 16)

// Whether plant `plant` is relief-mapped (render_cpu.cpp's scene_relief, relief.h).
bool relief_mapped(const ScenePlant& plant, const RenderOptions& options) {
  return options.geometry.relief && plant.bark.height_texture && plant.bark.relief_depth_m > 0;
}

// bark.glsl's PlantMaps, std430.
struct PlantMapsRecord {
  float u_repeat = 1, v_per_metre = 1, relief_depth_m = 0;
  int32_t albedo_unit = -1, height_unit = -1;
  uint32_t height_first = 0;
  int32_t height_width = 1, height_height = 1;
};
static_assert(sizeof(PlantMapsRecord) == 32, "bark.glsl's PlantMaps is 8 scalars");

// A scene's bark images on the GPU (bark.glsl): each distinct file once, as a texture with
// its full MIP chain bound at unit i for u_bark_textures[i] (albedo GL_RGBA8 with the
// file's sRGB-encoded values, decoded in the shader after filtering as texture.h does;
// height GL_R32F), the height maps' finest levels as floats (height_texels), one
// PlantMaps record per plant. Images are read with OpenImageIO as the CPU's
// TextureSystem reads them: 8-bit albedo, a gray albedo as gray RGB, height channel 0 as
// float in [0, 1], row 0 at t = 0.
struct BarkMaps {
  std::vector<PlantMapsRecord> plants;
  std::vector<GLuint> textures;  // unit i
  std::vector<float> height_texels;
  bool relief = false;  // some plant is relief-mapped (frusta geometry)
  bool albedo = false;  // some plant has an albedo texture
  uint64_t texture_bytes = 0;

  void load(const Scene& scene, const RenderOptions& options) {
    std::map<std::string, int> albedo_unit, height_unit;
    std::map<std::string, std::pair<uint32_t, glm::ivec2>> height_level;
    for (const ScenePlant& plant : scene.plants) {
      PlantMapsRecord r;
      r.u_repeat = static_cast<float>(plant.bark.u_repeat);
      r.v_per_metre = static_cast<float>(plant.bark.v_per_metre);
      if (plant.bark.albedo_texture) {
        const std::string& path = *plant.bark.albedo_texture;
        if (!albedo_unit.count(path)) albedo_unit[path] = upload(path, false);
        r.albedo_unit = albedo_unit[path];
        albedo = true;
      }
      if (relief_mapped(plant, options)) {
        // The shade pass offsets a relief plant's shadow lookups whatever the geometry
        // (render_cpu.cpp); the frusta pass marches it.
        r.relief_depth_m = static_cast<float>(plant.bark.relief_depth_m);
        if (options.geometry.kind == GeometryKind::frusta) {
          const std::string& path = *plant.bark.height_texture;
          if (!height_unit.count(path)) height_unit[path] = upload(path, true, &height_level[path]);
          r.height_unit = height_unit[path];
          r.height_first = height_level[path].first;
          r.height_width = height_level[path].second.x;
          r.height_height = height_level[path].second.y;
          relief = true;
        }
      }
      plants.push_back(r);
    }
  }

  // Reads `path` and makes its texture; returns its unit. A height map's finest level goes
  // to height_texels too (*level: its first texel and size).
  int upload(const std::string& path, bool height, std::pair<uint32_t, glm::ivec2>* level = nullptr) {
    if (textures.size() >= kMaxBarkImages) throw GlError("the GL backend binds at most 16 distinct bark images");
    auto input = OIIO::ImageInput::open(path);
    if (!input) throw GlError("cannot open texture '" + path + "': " + OIIO::geterror());
    const OIIO::ImageSpec spec = input->spec();
    const int w = std::max(1, spec.width), h = std::max(1, spec.height), channels = std::max(1, spec.nchannels);
    const size_t texels = static_cast<size_t>(w) * h;
    GLuint texture = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &texture);
    textures.push_back(texture);
    const int levels = 1 + static_cast<int>(std::floor(std::log2(std::max(w, h))));
    glTextureStorage2D(texture, levels, height ? GL_R32F : GL_RGBA8, w, h);
    if (height) {
      std::vector<float> values(texels);
      if (!input->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, values.data()))
        throw GlError("cannot read texture '" + path + "': " + input->geterror());
      glTextureSubImage2D(texture, 0, 0, 0, w, h, GL_RED, GL_FLOAT, values.data());
      *level = {static_cast<uint32_t>(height_texels.size()), glm::ivec2(w, h)};
      height_texels.insert(height_texels.end(), values.begin(), values.end());
      texture_bytes += texels * sizeof(float) * 7 / 3;  // the MIP chain and the texels
    } else {
      std::vector<uint8_t> values(texels * channels), rgba(texels * 4, 255);
      if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, values.data()))
        throw GlError("cannot read texture '" + path + "': " + input->geterror());
      for (size_t i = 0; i < texels; ++i)
        for (int k = 0; k < 3; ++k) rgba[i * 4 + k] = values[i * channels + (channels >= 3 ? k : 0)];
      glTextureSubImage2D(texture, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
      texture_bytes += texels * 4 * 4 / 3;
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
    return static_cast<int>(textures.size()) - 1;
  }
};

}  // namespace

std::optional<std::string> gl_unsupported(const Scene& scene, const RenderOptions& options) {
  std::set<std::string> images;  // what BarkMaps uploads
  for (const ScenePlant& plant : scene.plants) {
    if (plant.bark.albedo_texture) images.insert(*plant.bark.albedo_texture);
    if (options.geometry.kind == GeometryKind::frusta && relief_mapped(plant, options))
      images.insert(*plant.bark.height_texture);
  }
  if (images.size() > kMaxBarkImages)
    return "the GL backend binds at most " + std::to_string(kMaxBarkImages) + " distinct bark images (this scene has " +
           std::to_string(images.size()) + ")";
  return std::nullopt;
}

struct GlRenderer::State {
  RenderOptions options;
  std::vector<RenderPass> setup_passes;
  uint64_t frusta = 0;
  uint64_t uploaded_bytes = 0;
  std::vector<Sphere> spheres;  // around each frustum's bounding pyramid
  bool want_uv = false;
  FrustaFeatures features;  // the frusta program's switches for this scene (gl_shaders.h)
  BarkMaps bark_maps;
  GLuint maps_buffer = 0, height_texel_buffer = 0;
  std::unique_ptr<GlMesh> mesh;  // GeometryKind::mesh: the polygon baseline, drawn instead of the frusta
  size_t plant_count = 0;

  GLuint vao = 0;
  GLuint segment_buffer = 0, id_buffer = 0, list_buffer = 0, bark_buffer = 0;
  std::map<std::string, GlProgram> programs;

  uint32_t width = 0, height = 0;
  GLuint gbuffer_fbo = 0, gbuffer[4] = {0, 0, 0, 0}, depth_buffer = 0;  // + g_albedo (RGBA16F)
  GLuint accum_fbo = 0, accum = 0;
  int shadow_texels = 0;
  GLuint shadow_fbo = 0, shadow_map = 0;

  ~State() {
    for (auto& [name, program] : programs) glDeleteProgram(program.id);
    release_targets();
    release_shadow_map();
    const GLuint buffers[] = {segment_buffer, id_buffer, list_buffer, bark_buffer, maps_buffer, height_texel_buffer};
    glDeleteBuffers(6, buffers);
    if (!bark_maps.textures.empty())
      glDeleteTextures(static_cast<GLsizei>(bark_maps.textures.size()), bark_maps.textures.data());
    glDeleteVertexArrays(1, &vao);
  }

  // Skins every plant of `scene` into one record and one id quadruple (plant, chain,
  // segment, 0) per frustum, and replaces `spheres` with the frusta's bounding spheres.
  void skin_plants(const Scene& scene, std::vector<GpuSegment>* records, std::vector<uint32_t>* ids) {
    spheres.clear();
    for (uint32_t p = 0; p < scene.plants.size(); ++p) {
      if (!scene.plants[p].skeleton) throw std::logic_error("GlRenderer: a plant has no skeleton (call grow_scene_plants)");
      const SkinnedSkeleton skinned = skin_skeleton(place_plant(scene.plants[p]), options.skin);
      for (const Frustum& f : skinned.frusta) {
        records->push_back(pack_gpu_segment(f));
        ids->insert(ids->end(), {p, f.chain, f.segment, 0u});
        // A relief-mapped segment is drawn in the pyramid of its shell (frusta.vert.glsl).
        const float relief_depth_m = bark_maps.plants.empty() ? 0.0f : bark_maps.plants[p].relief_depth_m;
        const BoundingPyramid pyramid =
            bounding_pyramid(relief_depth_m > 0 && f.kind == FrustumKind::segment
                                 ? relief_shell(f.shape, relief_depth_m, options.geometry.relief_options.max_depth_per_radius)
                                 : f.shape);
        glm::dvec3 centre(0);
        for (const glm::dvec3& v : pyramid.vertices) centre += v / 8.0;
        double radius = 0;
        for (const glm::dvec3& v : pyramid.vertices) radius = std::max(radius, glm::length(v - centre));
        // The shader grows the pyramid by ~1e-4 of the frustum's size (frusta.vert.glsl).
        spheres.push_back({centre, radius * 1.001 + 1e-3 * (f.shape.length + std::max(f.shape.radius0, f.shape.radius1))});
      }
    }
  }

  ShaderProgramSource frusta_variant(FrustaPass pass) const { return frusta_program(pass, features); }

  // Binds what bark.glsl reads: the plant maps, the height texels, the images at units 0..
  void bind_bark_maps() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, maps_buffer);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, height_texel_buffer);
    for (size_t i = 0; i < bark_maps.textures.size(); ++i) glBindTextureUnit(static_cast<GLuint>(i), bark_maps.textures[i]);
  }

  // The program of a variant, built on first use (compile time goes to *compile_s).
  GLuint program(const ShaderProgramSource& source, double* compile_s) {
    auto found = programs.find(source.name);
    if (found != programs.end()) return found->second.id;
    const Clock::time_point start = Clock::now();
    GlProgram built = build_gl_program(source);
    if (compile_s) *compile_s += seconds_since(start);
    programs.emplace(source.name, built);
    return built.id;
  }

  void release_targets() {
    glDeleteFramebuffers(1, &gbuffer_fbo);
    glDeleteFramebuffers(1, &accum_fbo);
    glDeleteTextures(4, gbuffer);
    glDeleteTextures(1, &accum);
    glDeleteRenderbuffers(1, &depth_buffer);
    gbuffer_fbo = accum_fbo = accum = depth_buffer = 0;
    gbuffer[0] = gbuffer[1] = gbuffer[2] = gbuffer[3] = 0;
    width = height = 0;
  }

  void release_shadow_map() {
    glDeleteFramebuffers(1, &shadow_fbo);
    glDeleteTextures(1, &shadow_map);
    shadow_fbo = shadow_map = 0;
    shadow_texels = 0;
  }

  static void check_framebuffer(GLuint fbo, const char* what) {
    const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      char code[16];
      std::snprintf(code, sizeof code, "0x%04x", status);
      throw GlError(std::string(what) + " framebuffer incomplete (" + code + ")");
    }
  }

  void ensure_targets(uint32_t w, uint32_t h) {
    if (w == width && h == height) return;
    release_targets();
    GLint max_size = 0, max_renderbuffer = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
    max_size = std::min(max_size, max_renderbuffer);
    if (w > static_cast<uint32_t>(max_size) || h > static_cast<uint32_t>(max_size))
      throw GlError("image " + std::to_string(w) + "x" + std::to_string(h) + " exceeds the driver's largest target (" +
                    std::to_string(max_size) + " pixels a side)");
    const GLenum formats[4] = {GL_RGBA32F, GL_RGBA32F, GL_RGBA32UI, GL_RGBA16F};
    glCreateTextures(GL_TEXTURE_2D, 4, gbuffer);
    for (int i = 0; i < 4; ++i) {
      glTextureStorage2D(gbuffer[i], 1, formats[i], w, h);
      // texelFetch only, but an integer texture with a filtering mode is incomplete.
      glTextureParameteri(gbuffer[i], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(gbuffer[i], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glCreateRenderbuffers(1, &depth_buffer);
    glNamedRenderbufferStorage(depth_buffer, GL_DEPTH_COMPONENT32F, w, h);
    glCreateFramebuffers(1, &gbuffer_fbo);
    for (int i = 0; i < 4; ++i) glNamedFramebufferTexture(gbuffer_fbo, GL_COLOR_ATTACHMENT0 + i, gbuffer[i], 0);
    glNamedFramebufferRenderbuffer(gbuffer_fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_buffer);
    const GLenum draw_buffers[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                    GL_COLOR_ATTACHMENT3};
    glNamedFramebufferDrawBuffers(gbuffer_fbo, 4, draw_buffers);
    check_framebuffer(gbuffer_fbo, "G-buffer");
    glCreateTextures(GL_TEXTURE_2D, 1, &accum);
    glTextureStorage2D(accum, 1, GL_RGBA32F, w, h);
    glCreateFramebuffers(1, &accum_fbo);
    glNamedFramebufferTexture(accum_fbo, GL_COLOR_ATTACHMENT0, accum, 0);
    check_framebuffer(accum_fbo, "accumulation");
    check_gl("render targets");
    width = w;
    height = h;
  }

  void ensure_shadow_map(int texels) {
    if (texels == shadow_texels) return;
    release_shadow_map();
    glCreateTextures(GL_TEXTURE_2D, 1, &shadow_map);
    glTextureStorage2D(shadow_map, 1, GL_DEPTH_COMPONENT32F, texels, texels);
    glTextureParameteri(shadow_map, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(shadow_map, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glTextureParameteri(shadow_map, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(shadow_map, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(shadow_map, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(shadow_map, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float border[4] = {1, 1, 1, 1};
    glTextureParameterfv(shadow_map, GL_TEXTURE_BORDER_COLOR, border);
    glCreateFramebuffers(1, &shadow_fbo);
    glNamedFramebufferTexture(shadow_fbo, GL_DEPTH_ATTACHMENT, shadow_map, 0);
    glNamedFramebufferDrawBuffer(shadow_fbo, GL_NONE);
    check_framebuffer(shadow_fbo, "shadow map");
    check_gl("shadow map");
    shadow_texels = texels;
  }

  // The square orthographic view along `direction` that holds every frustum's sphere.
  ShadowFrame shadow_frame(const glm::dvec3& direction, int texels) const {
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
};

GlRenderer::GlRenderer(const Scene& scene, const RenderOptions& options) : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.options = options;
  st.want_uv = (options.aovs & kAovUv) != 0;
  if (scene.plants.size() >= kMaxPlants) throw GlError("the GL backend draws at most 2^24 plants");
  st.plant_count = scene.plants.size();

  // Bark images first: the relief's shells set the pyramids' bounding spheres.
  Clock::time_point start = Clock::now();
  st.bark_maps.load(scene, options);
  st.features.want_uv = st.want_uv;
  st.features.relief = st.bark_maps.relief;
  st.features.bark = st.bark_maps.albedo;
  st.features.texture_units = static_cast<int>(st.bark_maps.textures.size());
  if (!st.bark_maps.textures.empty())
    st.setup_passes.push_back({"textures", seconds_since(start),
                               std::to_string(st.bark_maps.textures.size()) + " images, " +
                                   std::to_string(st.bark_maps.texture_bytes / 1024) + " KiB with MIP chains"});

  start = Clock::now();
  std::vector<GpuSegment> records;
  std::vector<uint32_t> ids;  // plant, chain, segment, 0 per frustum
  if (options.geometry.kind == GeometryKind::mesh) {
    // The polygon baseline (gl_mesh.h): its own skin, tessellate, displace, upload, programs.
    st.mesh = std::make_unique<GlMesh>(scene, options, st.bark_maps.albedo ? st.features.texture_units : 0);
    for (const GlMeshSphere& s : st.mesh->bounding_spheres()) st.spheres.push_back({s.centre, s.radius});
    st.frusta = st.mesh->frusta();
    st.setup_passes = st.mesh->setup_passes();
  } else {
    st.skin_plants(scene, &records, &ids);
    st.frusta = records.size();
    st.setup_passes.push_back({"skin", seconds_since(start),
                               std::to_string(scene.plants.size()) + " plants, " + std::to_string(st.frusta) + " frusta"});
  }

  start = Clock::now();
  glCreateVertexArrays(1, &st.vao);
  // The segment records may be rewritten in place (update_plants).
  st.segment_buffer = make_buffer(records.data(), records.size() * sizeof(GpuSegment), GL_DYNAMIC_STORAGE_BIT);
  st.id_buffer = make_buffer(ids.data(), ids.size() * sizeof(uint32_t));
  std::vector<float> bark;
  for (const ScenePlant& plant : scene.plants) {
    if (plant.bark.albedo_rgb)
      bark.insert(bark.end(), {static_cast<float>(plant.bark.albedo_rgb->x), static_cast<float>(plant.bark.albedo_rgb->y),
                               static_cast<float>(plant.bark.albedo_rgb->z), 1.0f});
    else
      bark.insert(bark.end(), {0.0f, 0.0f, 0.0f, 0.0f});
  }
  st.bark_buffer = make_buffer(bark.data(), bark.size() * sizeof(float));
  st.maps_buffer = make_buffer(st.bark_maps.plants.data(), st.bark_maps.plants.size() * sizeof(PlantMapsRecord));
  st.height_texel_buffer =
      make_buffer(st.bark_maps.height_texels.data(), st.bark_maps.height_texels.size() * sizeof(float));
  glCreateBuffers(1, &st.list_buffer);
  check_gl("upload");
  if (st.mesh) {
    st.uploaded_bytes = st.mesh->gpu_bytes();  // its "upload" pass is in already
  } else {
    st.uploaded_bytes = records.size() * sizeof(GpuSegment) + ids.size() * sizeof(uint32_t);
    st.setup_passes.push_back({"upload", seconds_since(start),
                               std::to_string(st.uploaded_bytes / 1024) + " KiB: " + std::to_string(st.frusta) +
                                   " GpuSegment records (64 B) + ids (16 B)"});
  }

  // What every frame needs; EYE_INSIDE is built when a frame needs it.
  double compile_s = 0;
  const bool sun_on = scene.sun.radiance.x > 0 || scene.sun.radiance.y > 0 || scene.sun.radiance.z > 0;
  std::string names;
  std::vector<ShaderProgramSource> needed = {st.frusta_variant(FrustaPass::gbuffer), shade_program(sun_on)};
  if (sun_on) needed.push_back(st.frusta_variant(FrustaPass::shadow));
  if (st.mesh) needed = {shade_program(sun_on)};  // the mesh built its own
  for (const ShaderProgramSource& source : needed) {
    st.program(source, &compile_s);
    names += (names.empty() ? "" : ", ") + source.name;
  }
  st.setup_passes.push_back({"programs", compile_s, names});
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  check_gl("setup");
}

GlRenderer::~GlRenderer() = default;

void GlRenderer::set_conservative_depth(bool on) { state_->features.conservative_depth = on; }

uint64_t GlRenderer::frusta() const { return state_->frusta; }
uint64_t GlRenderer::uploaded_bytes() const { return state_->uploaded_bytes; }
const std::vector<RenderPass>& GlRenderer::setup_passes() const { return state_->setup_passes; }

uint64_t GlRenderer::update_plants(const Scene& scene) {
  State& st = *state_;
  if (scene.plants.size() != st.plant_count)
    throw std::invalid_argument("GlRenderer::update_plants: the scene has " + std::to_string(scene.plants.size()) +
                                " plants, the renderer " + std::to_string(st.plant_count));
  if (st.mesh) {  // the polygon baseline is re-tessellated and uploaded whole
    const uint64_t uploaded = st.mesh->update(scene);
    st.spheres.clear();
    for (const GlMeshSphere& s : st.mesh->bounding_spheres()) st.spheres.push_back({s.centre, s.radius});
    st.frusta = st.mesh->frusta();
    st.uploaded_bytes = st.mesh->gpu_bytes();
    return uploaded;
  }
  std::vector<GpuSegment> records;
  std::vector<uint32_t> ids;
  st.skin_plants(scene, &records, &ids);
  const size_t record_bytes = records.size() * sizeof(GpuSegment);
  uint64_t uploaded = record_bytes;
  if (records.size() == st.frusta) {
    if (record_bytes) glNamedBufferSubData(st.segment_buffer, 0, static_cast<GLsizeiptr>(record_bytes), records.data());
  } else {
    // The topology changed (a frustum more or less): new buffers, ids included.
    const GLuint old[2] = {st.segment_buffer, st.id_buffer};
    glDeleteBuffers(2, old);
    st.segment_buffer = make_buffer(records.data(), record_bytes, GL_DYNAMIC_STORAGE_BIT);
    st.id_buffer = make_buffer(ids.data(), ids.size() * sizeof(uint32_t));
    uploaded += ids.size() * sizeof(uint32_t);
    st.frusta = records.size();
    st.uploaded_bytes = record_bytes + ids.size() * sizeof(uint32_t);
  }
  check_gl("update_plants");
  return uploaded;
}

RenderResult GlRenderer::render(const Scene& scene) {
  State& st = *state_;
  const RenderOptions& options = st.options;
  RenderResult result;
  result.frusta = st.frusta;
  result.geometry_bytes = st.uploaded_bytes;
  const Clock::time_point frame_start = Clock::now();
  const uint32_t w = scene.width, h = scene.height;
  st.ensure_targets(w, h);

  const CameraFrame camera = camera_frame(scene);
  const SplitVec3 eye = split(camera.eye);
  const bool sun_on = scene.sun.radiance.x > 0 || scene.sun.radiance.y > 0 || scene.sun.radiance.z > 0;
  const glm::dvec3 sun_direction = glm::normalize(scene.sun.direction);
  const AxisFrame sun_frame = axis_frame(sun_direction);
  const double cos_alpha = std::cos(scene.sun.angular_radius_deg * kPi / 180);
  const uint32_t spp = std::max(1u, options.spp);
  const bool sun_per_pass = sun_on && spp > 1 && scene.sun.angular_radius_deg > 0;

  // Reversed-Z near plane: far below any hit that matters, far above float's smallest.
  double farthest = 1e-3;
  for (const Sphere& s : st.spheres) farthest = std::max(farthest, glm::length(s.centre - camera.eye) + s.radius);
  const double near = 1e-6 * farthest;
  // Frusta whose pyramid may reach within the near plane of the eye: drawn again from
  // their back faces (EYE_INSIDE), since their front faces are clipped or behind the eye.
  std::vector<uint32_t> eye_inside;
  for (uint32_t i = 0; !st.mesh && i < st.spheres.size(); ++i)
    if (glm::length(st.spheres[i].centre - camera.eye) < st.spheres[i].radius + 4 * near) eye_inside.push_back(i);
  if (!eye_inside.empty())
    glNamedBufferData(st.list_buffer, static_cast<GLsizeiptr>(eye_inside.size() * sizeof(uint32_t)), eye_inside.data(),
                      GL_STREAM_DRAW);

  double compile_s = 0;
  const GLuint gbuffer_program = st.mesh ? 0 : st.program(st.frusta_variant(FrustaPass::gbuffer), &compile_s);
  const GLuint inside_program =
      eye_inside.empty() ? 0 : st.program(st.frusta_variant(FrustaPass::gbuffer_eye_inside), &compile_s);
  const GLuint shadow_program =
      sun_on && !st.mesh ? st.program(st.frusta_variant(FrustaPass::shadow), &compile_s) : 0;
  const GLuint shade = st.program(shade_program(sun_on), &compile_s);

  // Uniforms that stay for the frame.
  for (GLuint p : {gbuffer_program, inside_program, shade}) {
    if (!p) continue;
    set_uniform(p, "u_eye_hi", eye.hi);
    set_uniform(p, "u_eye_lo", eye.lo);
    set_uniform(p, "u_right", camera.right);
    set_uniform(p, "u_up", camera.up);
    set_uniform(p, "u_forward", camera.forward);
    set_uniform(p, "u_half_size", camera.half_width, camera.half_height);
    set_uniform(p, "u_image_size", w, h);
    set_uniform(p, "u_near", near);
  }
  // Ray differentials (texture.h): the next sample to the right / below, one pixel /
  // sqrt(spp) away, as render_cpu.cpp's direction_dx_, direction_dy_.
  const double differential_step = 1 / std::sqrt(static_cast<double>(spp));
  const glm::dvec3 ray_dx = (differential_step * 2 * camera.half_width / w) * camera.right;
  const glm::dvec3 ray_dy = (-differential_step * 2 * camera.half_height / h) * camera.up;
  const ReliefOptions& relief = options.geometry.relief_options;
  for (GLuint p : {gbuffer_program, inside_program, shadow_program}) {
    if (!p) continue;
    set_uniform(p, "u_twist_rad_per_m", options.skin.twist_rad_per_m);
    set_uniform(p, "u_ray_dx", ray_dx);
    set_uniform(p, "u_ray_dy", ray_dy);
    set_uniform_int(p, "u_relief_linear_steps", std::max(1, relief.linear_steps));
    set_uniform_int(p, "u_relief_bisection_steps", std::max(0, relief.bisection_steps));
    set_uniform_int(p, "u_relief_exact_v", relief.exact_v ? 1 : 0);
    set_uniform(p, "u_relief_max_depth_per_radius", relief.max_depth_per_radius);
    // render_cpu.cpp's pixel_spread_rad: the angle between neighbouring samples' rays.
    set_uniform(p, "u_relief_pixel_spread_rad", glm::length(ray_dy));
  }
  set_uniform(shade, "u_pixel_step_rad", glm::length(ray_dy));
  set_uniform(shade, "u_eye_above_ground", camera.eye.y - scene.ground.height);
  set_uniform(shade, "u_sky", scene.sky);
  set_uniform(shade, "u_ground_albedo", scene.ground.albedo);
  {
    glm::vec3 albedo[kMaxMaterials];
    const int count = std::min<int>(kMaterialTableSize, kMaxMaterials);
    for (int i = 0; i < count; ++i) {
      const double* a = default_material_albedo(static_cast<uint32_t>(i));
      albedo[i] = glm::vec3(static_cast<float>(a[0]), static_cast<float>(a[1]), static_cast<float>(a[2]));
    }
    glProgramUniform3fv(shade, location(shade, "u_material_albedo"), count, &albedo[0].x);
    set_uniform_int(shade, "u_material_count", count);
  }

  int shadow_texels = 0;
  if (sun_on) {
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    // A texel about a pixel where the plants fill the picture (the default framing); the
    // map's fill dominates a frame on llvmpipe.
    int texels = kShadowTexelsMin;
    while (texels < static_cast<int>(std::max(w, h)) && texels < kShadowTexelsMax) texels *= 2;
    shadow_texels = std::min(texels, max_size);
    st.ensure_shadow_map(shadow_texels);
  }

  glBindVertexArray(st.vao);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, st.segment_buffer);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, st.id_buffer);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, st.list_buffer);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, st.bark_buffer);
  st.bind_bark_maps();
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_STENCIL_TEST);
  glDepthMask(GL_TRUE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glFrontFace(GL_CCW);
  const GLsizei vertices = static_cast<GLsizei>(st.frusta * 36);

  PassTimer shadow_timer, frusta_timer, shade_timer;
  auto draw_shadow_map = [&](const ShadowFrame& f) {
    shadow_timer.begin();
    glBindFramebuffer(GL_FRAMEBUFFER, st.shadow_fbo);
    glViewport(0, 0, shadow_texels, shadow_texels);
    const float one = 1;
    glClearNamedFramebufferfv(st.shadow_fbo, GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    if (st.mesh) {
      st.mesh->draw_shadow({f.centre, f.e0, f.e1, f.direction, f.x_min, f.y_min, f.side, f.s_near, f.s_range});
      PassTimer::end();
      return;
    }
    const SplitVec3 c = split(f.centre);
    set_uniform(shadow_program, "u_light_hi", c.hi);
    set_uniform(shadow_program, "u_light_lo", c.lo);
    set_uniform(shadow_program, "u_light_e0", f.e0);
    set_uniform(shadow_program, "u_light_e1", f.e1);
    set_uniform(shadow_program, "u_light_dir", f.direction);
    set_uniform(shadow_program, "u_light_rect", f.x_min, f.y_min, f.side, f.side);
    set_uniform(shadow_program, "u_light_depth", f.s_near, f.s_range);
    set_uniform(shadow_program, "u_map_size", shadow_texels, shadow_texels);
    glUseProgram(shadow_program);
    if (vertices > 0) glDrawArrays(GL_TRIANGLES, 0, vertices);
    PassTimer::end();
  };
  auto draw_gbuffer = [&](double jitter_x, double jitter_y) {
    frusta_timer.begin();
    glBindFramebuffer(GL_FRAMEBUFFER, st.gbuffer_fbo);
    glViewport(0, 0, static_cast<GLsizei>(w), static_cast<GLsizei>(h));
    const float miss[4] = {0, 0, 0, -1}, zero[4] = {0, 0, 0, 0}, far_depth = 0;
    const GLuint zero_ids[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(st.gbuffer_fbo, GL_COLOR, 0, miss);
    glClearNamedFramebufferfv(st.gbuffer_fbo, GL_COLOR, 1, zero);
    glClearNamedFramebufferuiv(st.gbuffer_fbo, GL_COLOR, 2, zero_ids);
    glClearNamedFramebufferfv(st.gbuffer_fbo, GL_COLOR, 3, zero);
    glClearNamedFramebufferfv(st.gbuffer_fbo, GL_DEPTH, 0, &far_depth);
    st.bind_bark_maps();  // the shade pass took units 0..4
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    if (st.mesh) {
      st.mesh->draw_gbuffer({camera.eye, camera.right, camera.up, camera.forward, camera.half_width, camera.half_height,
                             w, h, near, jitter_x, jitter_y, differential_step});
      PassTimer::end();
      return;
    }
    set_uniform(gbuffer_program, "u_jitter", jitter_x, jitter_y);
    glUseProgram(gbuffer_program);
    if (vertices > 0) glDrawArrays(GL_TRIANGLES, 0, vertices);
    if (inside_program) {
      glCullFace(GL_FRONT);
      set_uniform(inside_program, "u_jitter", jitter_x, jitter_y);
      glUseProgram(inside_program);
      glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(eye_inside.size() * 36));
    }
    PassTimer::end();
  };

  const float black[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(st.accum_fbo, GL_COLOR, 0, black);
  const uint32_t grid_x = static_cast<uint32_t>(std::ceil(std::sqrt(static_cast<double>(spp))));
  const uint32_t grid_y = (spp + grid_x - 1) / grid_x;
  ShadowFrame shadow{};
  for (uint32_t sample = 0; sample < spp; ++sample) {
    if (options.cancel && options.cancel->load()) {
      result.cancelled = true;
      glFinish();
      for (PassTimer* timer : {&shadow_timer, &frusta_timer, &shade_timer}) timer->seconds();  // frees the queries
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      return result;
    }
    // The CPU's stratified grid, one offset per pass; the sun's disc sampled as the CPU's
    // sun_sample does (uniform in solid angle).
    render_common::SampleRng rng(0x5EED0000ull + sample * 0x9E37ull);
    double jitter_x = 0.5, jitter_y = 0.5;
    if (spp > 1) {
      jitter_x = ((sample % grid_x) + rng.next_double()) / grid_x;
      jitter_y = ((sample / grid_x) + rng.next_double()) / grid_y;
    }
    glm::dvec3 l = sun_direction;
    if (sun_per_pass) {
      l = render_common::sample_sun_disc(sun_direction, cos_alpha, sun_frame, rng);
    }
    if (sun_on && (sample == 0 || sun_per_pass)) {
      shadow = st.shadow_frame(l, shadow_texels);
      draw_shadow_map(shadow);
    }
    draw_gbuffer(jitter_x, jitter_y);

    shade_timer.begin();
    glBindFramebuffer(GL_FRAMEBUFFER, st.accum_fbo);
    glViewport(0, 0, static_cast<GLsizei>(w), static_cast<GLsizei>(h));
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBindTextureUnit(0, st.gbuffer[0]);
    glBindTextureUnit(1, st.gbuffer[1]);
    glBindTextureUnit(2, st.gbuffer[2]);
    glBindTextureUnit(4, st.gbuffer[3]);
    set_uniform(shade, "u_jitter", jitter_x, jitter_y);
    if (sun_on) {
      glBindTextureUnit(3, st.shadow_map);
      set_uniform(shade, "u_sun_dir", l);
      set_uniform(shade, "u_sun_radiance", scene.sun.radiance);
      set_uniform(shade, "u_eye_rel_light", camera.eye - shadow.centre);
      set_uniform(shade, "u_light_e0", shadow.e0);
      set_uniform(shade, "u_light_e1", shadow.e1);
      set_uniform(shade, "u_light_rect", shadow.x_min, shadow.y_min, shadow.side, shadow.side);
      set_uniform(shade, "u_light_depth", shadow.s_near, shadow.s_range);
      set_uniform(shade, "u_normal_offset_m", kShadowNormalOffsetTexels * shadow.texel_m);
      set_uniform(shade, "u_depth_bias", kShadowDepthBiasTexels * shadow.texel_m / shadow.s_range);
    }
    glUseProgram(shade);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_BLEND);
    PassTimer::end();
  }
  // AOVs describe the pixel centres: the last G-buffer already is that at 1 spp.
  if (options.aovs && spp > 1) draw_gbuffer(0.5, 0.5);
  check_gl("frame");

  // Read back, flipping GL's bottom-up rows (after the GPU is done, so that "readback" is
  // the transfer alone).
  glFinish();
  const Clock::time_point readback_start = Clock::now();
  const size_t pixels = static_cast<size_t>(w) * h;
  RenderImage& image = result.image;
  image.width = w;
  image.height = h;
  std::vector<float> rgba(pixels * 4);
  glGetTextureImage(st.accum, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(rgba.size() * sizeof(float)), rgba.data());
  image.beauty.resize(pixels * 4);
  const float inv_spp = 1.0f / static_cast<float>(spp);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const float* src = &rgba[(static_cast<size_t>(h - 1 - y) * w + x) * 4];
      float* dst = &image.beauty[(static_cast<size_t>(y) * w + x) * 4];
      for (int k = 0; k < 3; ++k) dst[k] = src[k] * inv_spp;
      dst[3] = 1;
    }
  if (options.aovs) {
    std::vector<float> g0(pixels * 4), g1(pixels * 4);
    std::vector<uint32_t> g2(pixels * 4);
    glGetTextureImage(st.gbuffer[0], 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(g0.size() * sizeof(float)), g0.data());
    glGetTextureImage(st.gbuffer[1], 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(g1.size() * sizeof(float)), g1.data());
    glGetTextureImage(st.gbuffer[2], 0, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                      static_cast<GLsizei>(g2.size() * sizeof(uint32_t)), g2.data());
    if (options.aovs & kAovDepth) image.depth.assign(pixels, 0.0f);
    if (options.aovs & kAovNormal) image.normal.assign(pixels * 3, 0.0f);
    if (options.aovs & kAovUv) image.uv.assign(pixels * 2, 0.0f);
    if (options.aovs & kAovId) image.id.assign(pixels * 3, 0.0f);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        const size_t src = static_cast<size_t>(h - 1 - y) * w + x, dst = static_cast<size_t>(y) * w + x;
        const bool hit = g0[src * 4 + 3] >= 0;
        if (!image.depth.empty())
          image.depth[dst] = hit ? g0[src * 4 + 3] : std::numeric_limits<float>::infinity();
        if (!image.normal.empty())
          for (int k = 0; k < 3; ++k) image.normal[dst * 3 + k] = hit ? g0[src * 4 + k] : 0.0f;
        if (!image.uv.empty() && hit) {
          float v_m = 0;
          std::memcpy(&v_m, &g2[src * 4 + 3], sizeof v_m);
          image.uv[dst * 2 + 0] = g1[src * 4 + 3];
          image.uv[dst * 2 + 1] = v_m;
        }
        if (!image.id.empty()) {
          image.id[dst * 3 + 0] = hit ? static_cast<float>(g2[src * 4 + 0] & 0xFFFFFFu) : -1.0f;
          image.id[dst * 3 + 1] = hit ? static_cast<float>(g2[src * 4 + 1]) : -1.0f;
          image.id[dst * 3 + 2] = hit ? static_cast<float>(g2[src * 4 + 2]) : -1.0f;
        }
      }
  }
  check_gl("readback");
  const double readback_s = seconds_since(readback_start);

  const double shadow_s = shadow_timer.seconds(), frusta_s = frusta_timer.seconds(), shade_s = shade_timer.seconds();
  if (compile_s > 0) result.passes.push_back({"programs", compile_s, "built for this frame"});
  if (sun_on)
    result.passes.push_back({"shadow map (GPU)", shadow_s,
                             std::to_string(shadow_texels) + "x" + std::to_string(shadow_texels) + ", " +
                                 std::to_string(sun_per_pass ? spp : 1) + " pass(es), " +
                                 (st.mesh ? mesh_program(MeshPass::shadow) : st.frusta_variant(FrustaPass::shadow)).name});
  if (st.mesh)
    result.passes.push_back({"mesh (GPU)", frusta_s,
                             std::to_string(st.mesh->triangles()) + " triangles (" + st.mesh->label() + "), " +
                                 std::to_string(spp + (options.aovs && spp > 1)) + " pass(es), " +
                                 st.mesh->gbuffer_variant()});
  else
    result.passes.push_back({"frusta (GPU)", frusta_s,
                             std::to_string(st.frusta) + " frusta, " + std::to_string(spp + (options.aovs && spp > 1)) +
                                 " pass(es), " + st.frusta_variant(FrustaPass::gbuffer).name +
                                 (eye_inside.empty() ? "" : ", " + std::to_string(eye_inside.size()) + " around the eye")});
  result.passes.push_back({"shade (GPU)", shade_s, std::to_string(spp) + " pass(es), " + shade_program(sun_on).name});
  result.passes.push_back({"readback", readback_s, std::to_string(w) + "x" + std::to_string(h)});
  result.passes.push_back({"frame (wall)", seconds_since(frame_start), ""});
  result.primary_rays = pixels * spp;
  result.shadow_rays = 0;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glUseProgram(0);
  glBindVertexArray(0);
  return result;
}

RenderResult render_gl(const Scene& scene, const RenderOptions& options) {
  if (auto why = gl_unsupported(scene, options)) throw GlError(*why);
  GlRenderer renderer(scene, options);
  RenderResult result = renderer.render(scene);
  result.passes.insert(result.passes.begin(), renderer.setup_passes().begin(), renderer.setup_passes().end());
  return result;
}

}  // namespace sylva
