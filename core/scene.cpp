// scene.cpp — reading scene.md's `.scene.json`, and the default scene around a skeleton.
#include "core/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

#include "core/fog.h"
#include "core/leaf_mesh.h"
#include "core/materials.h"
#include "core/util/diagnostic.h"
#include "core/util/file_io.h"
#include "core/util/json.h"
#include "core/util/limits.h"
#include "core/util/image_io.h"
#include "core/turtle.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sylva {

const char* fog_mode_name(FogMode mode) {
  switch (mode) {
    case FogMode::automatic: return "auto";
    case FogMode::brute: return "brute";
    case FogMode::medium: return "medium";
    case FogMode::fast: return "fast";
    case FogMode::refined: return "refined";
    case FogMode::reference: return "reference";
  }
  return "auto";
}

std::optional<FogMode> fog_mode_from_name(std::string_view name) {
  for (FogMode m : {FogMode::automatic, FogMode::brute, FogMode::medium, FogMode::fast, FogMode::refined,
                    FogMode::reference})
    if (name == fog_mode_name(m)) return m;
  return std::nullopt;
}

namespace {

// Thrown inside this file only; parse_scene_json turns it into a Diagnostic.
struct Located {
  uint32_t line, column;
  std::string message;
};

[[noreturn]] void fail(const JsonValue& at, std::string message) {
  throw Located{at.line, at.column, std::move(message)};
}

// Rejects members not in `known`, at the key's place.
void check_keys(const JsonValue& object, std::string_view what,
                std::initializer_list<std::string_view> known) {
  for (const JsonMember& m : object.members) {
    if (std::find(known.begin(), known.end(), m.key.name) != known.end()) continue;
    std::string list;
    for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    throw Located{m.key.line, m.key.column,
                  "unknown key " + json_excerpt(m.key.name) + " in " + std::string(what) +
                      " (known keys: " + list + ")"};
  }
}

const JsonValue& expect_object(const JsonValue& v, std::string_view what) {
  if (!v.is_object()) fail(v, std::string(what) + " must be an object, not " + v.kind_name());
  return v;
}

double number(const JsonValue& v, std::string_view what) {
  if (!v.is_number()) fail(v, std::string(what) + " must be a number, not " + v.kind_name());
  return v.number;  // the parser rejects non-finite numbers
}

double number_in(const JsonValue& v, std::string_view what, double lo, double hi,
                 bool open_lo, bool open_hi) {
  double x = number(v, what);
  if ((open_lo ? x <= lo : x < lo) || (open_hi ? x >= hi : x > hi)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, " must be in %s%g, %g%s", open_lo ? "(" : "[", lo, hi,
                  open_hi ? ")" : "]");
    fail(v, std::string(what) + buf + ", not " + v.text);
  }
  return x;
}

glm::dvec3 vec3(const JsonValue& v, std::string_view what) {
  if (!v.is_array() || v.elements.size() != 3)
    fail(v, std::string(what) + " must be an array of 3 numbers");
  return {number(v.elements[0], what), number(v.elements[1], what), number(v.elements[2], what)};
}

// A point in the world: each coordinate within kMaxCoordinateM (docs/limits.md).
glm::dvec3 point(const JsonValue& v, std::string_view what) {
  glm::dvec3 p = vec3(v, what);
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(p[k]) <= kMaxCoordinateM))
      fail(v.elements[k], std::string(what) + " coordinates must be within ±1e12 m (docs/limits.md), not " +
                              v.elements[k].text);
  return p;
}

glm::dvec3 colour(const JsonValue& v, std::string_view what) {
  glm::dvec3 c = vec3(v, what);
  for (int k = 0; k < 3; ++k)
    if (c[k] < 0) fail(v.elements[k], std::string(what) + " components must be >= 0");
  return c;
}

uint32_t image_size(const JsonValue& v, std::string_view what) {
  auto n = v.as_uint64();
  if (!n || *n == 0 || *n > kMaxImageSide) fail(v, std::string(what) + " must be an integer from 1 to 65536");
  return static_cast<uint32_t>(*n);
}

std::string path_relative_to(const std::string& base_dir, const JsonValue& v, std::string_view what) {
  if (!v.is_string() || v.text.empty()) fail(v, std::string(what) + " must be a non-empty path string");
  std::filesystem::path p(v.text);
  if (p.is_absolute() || base_dir.empty()) return v.text;
  return (std::filesystem::path(base_dir) / p).lexically_normal().string();
}

Camera read_camera(const JsonValue& v) {
  expect_object(v, "camera");
  check_keys(v, "camera", {"eye", "target", "up", "fov_y_deg"});
  Camera c;
  if (auto* x = v.find("eye")) c.eye = point(*x, "camera.eye");
  if (auto* x = v.find("target")) c.target = point(*x, "camera.target");
  if (auto* x = v.find("up")) c.up = vec3(*x, "camera.up");
  if (auto* x = v.find("fov_y_deg")) c.fov_y_deg = number_in(*x, "camera.fov_y_deg", 0, 180, true, true);
  glm::dvec3 forward = c.target - c.eye;
  if (!(glm::length(forward) > 0)) fail(v, "camera.eye and camera.target must differ");
  // Compared as unit vectors, so that an up of [0, 1e300, 0] is not taken for parallel.
  const std::optional<glm::dvec3> up = rescaled_direction(c.up);
  if (!up) fail(v, "camera.up must not be zero");
  c.up = *up;
  glm::dvec3 side = glm::cross(glm::normalize(forward), glm::normalize(*up));
  if (!(glm::length(side) > 1e-9))
    fail(v, "camera.up must not be parallel to the view direction");
  return c;
}

Sun read_sun(const JsonValue& v) {
  expect_object(v, "sun");
  check_keys(v, "sun", {"direction", "angular_radius_deg", "radiance"});
  Sun s;
  if (auto* x = v.find("direction")) {
    const std::optional<glm::dvec3> direction = rescaled_direction(vec3(*x, "sun.direction"));
    if (!direction) fail(*x, "sun.direction must not be zero");
    s.direction = *direction;
  }
  s.direction = glm::normalize(s.direction);
  if (auto* x = v.find("angular_radius_deg"))
    s.angular_radius_deg = number_in(*x, "sun.angular_radius_deg", 0, 45, false, false);
  if (auto* x = v.find("radiance")) s.radiance = colour(*x, "sun.radiance");
  return s;
}

// A texture named by member `key` of `object` must exist and open in OpenImageIO, so a
// missing or broken image is reported at its key, before anything is grown or rendered.
void check_texture(const JsonValue& object, std::string_view key, const std::string& path,
                   const std::string& what) {
  const JsonMember* member = nullptr;
  for (const JsonMember& m : object.members)
    if (m.key.name == key) member = &m;
  const uint32_t line = member ? member->key.line : object.line;
  const uint32_t column = member ? member->key.column : object.column;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw Located{line, column, what + ": no such image file '" + path + "'"};
  if (Status opens = check_image_opens(path); !opens)
    throw Located{line, column, what + ": cannot open image '" + path + "': " + opens.error().message};
}

Bark read_bark(const JsonValue& v, const std::string& base_dir, std::string_view what) {
  expect_object(v, what);
  check_keys(v, what, {"albedo", "height", "relief_depth", "u_repeat", "v_per_metre"});
  Bark b;
  if (auto* x = v.find("albedo")) {
    if (x->is_array()) {
      b.albedo_rgb = colour(*x, "bark.albedo");
    } else {
      b.albedo_texture = path_relative_to(base_dir, *x, "bark.albedo");
      check_texture(v, "albedo", *b.albedo_texture, std::string(what) + ".albedo");
    }
  }
  if (auto* x = v.find("height")) {
    b.height_texture = path_relative_to(base_dir, *x, "bark.height");
    check_texture(v, "height", *b.height_texture, std::string(what) + ".height");
  }
  if (auto* x = v.find("relief_depth")) b.relief_depth_m = number_in(*x, "bark.relief_depth", 0, 1e3, false, false);
  if (auto* x = v.find("u_repeat")) b.u_repeat = number_in(*x, "bark.u_repeat", 0, 1e6, true, false);
  if (auto* x = v.find("v_per_metre")) b.v_per_metre = number_in(*x, "bark.v_per_metre", 0, 1e6, true, false);
  return b;
}

// The `materials` table (docs/materials.md): an array of entries, each naming its index
// once.
std::map<uint32_t, SceneMaterial> read_materials(const JsonValue& v) {
  if (!v.is_array()) fail(v, std::string("materials must be an array, not ") + v.kind_name());
  std::map<uint32_t, SceneMaterial> table;
  for (size_t i = 0; i < v.elements.size(); ++i) {
    const JsonValue& e = v.elements[i];
    const std::string what = "materials[" + std::to_string(i) + "]";
    expect_object(e, what);
    check_keys(e, what, {"index", "albedo", "specular"});
    const JsonValue* index = e.find("index");
    if (!index) fail(e, what + " needs an \"index\" (the material index it describes)");
    const std::optional<uint64_t> k = index->as_uint64();
    if (!k || *k >= kMaterialSlots)
      fail(*index, what + ".index must be an integer from 0 to " + std::to_string(kMaterialSlots - 1));
    if (table.count(static_cast<uint32_t>(*k)))
      fail(*index, what + ".index " + std::to_string(*k) + " is described twice");
    SceneMaterial m;
    if (auto* x = e.find("albedo")) m.albedo_rgb = colour(*x, what + ".albedo");
    if (auto* x = e.find("specular")) m.specular = number_in(*x, what + ".specular", 0, 1, false, false);
    table.emplace(static_cast<uint32_t>(*k), m);
  }
  return table;
}

ScenePlant read_plant(const JsonValue& v, const std::string& base_dir, size_t index) {
  const std::string what = "plants[" + std::to_string(index) + "]";
  expect_object(v, what);
  check_keys(v, what, {"grammar", "seed", "steps", "defines", "position", "rotate_y_deg", "scale", "bark"});
  ScenePlant p;
  const JsonValue* g = v.find("grammar");
  if (!g) fail(v, what + " needs a \"grammar\"");
  p.grammar = path_relative_to(base_dir, *g, what + ".grammar");
  p.grammar_loc = {g->line, g->column};
  if (auto* x = v.find("seed")) {
    auto s = x->as_uint64();
    if (!s) fail(*x, what + ".seed must be an integer from 0 to 18446744073709551615");
    p.seed = *s;
  }
  if (auto* x = v.find("steps")) {
    auto s = x->as_uint64();
    if (!s || *s > 1000000) fail(*x, what + ".steps must be an integer from 0 to 1000000");
    p.steps = static_cast<int64_t>(*s);
  }
  if (auto* x = v.find("defines")) {
    expect_object(*x, what + ".defines");
    for (const JsonMember& m : x->members) p.defines[m.key.name] = number(m.value, what + ".defines." + m.key.name);
  }
  if (auto* x = v.find("position")) p.position = point(*x, what + ".position");
  if (auto* x = v.find("rotate_y_deg")) p.rotate_y_deg = number(*x, what + ".rotate_y_deg");
  if (auto* x = v.find("scale")) p.scale = number_in(*x, what + ".scale", 0, 1e9, true, false);
  if (auto* x = v.find("bark")) p.bark = read_bark(*x, base_dir, what + ".bark");
  return p;
}

// The `fog` object (spec/fog.md). Every key out of range is reported at the key (its line
// and column), so the message points at what to change.
Fog read_fog(const JsonValue& v, double ground_height) {
  expect_object(v, "fog");
  check_keys(v, "fog", {"sigma_s", "sigma_a", "g", "height_falloff", "top", "mode", "steps", "photons"});
  Fog f;
  for (const JsonMember& m : v.members) {
    const std::string& key = m.key.name;
    const JsonValue& value = m.value;
    const std::string what = "fog." + key;
    auto at_key = [&](const std::string& message) -> Located { return Located{m.key.line, m.key.column, message}; };
    // What the file says, for the message: a number's source text, a quoted string, a kind.
    const std::string shown = value.is_number()   ? value.text
                              : value.is_string() ? json_excerpt(value.text)
                                                  : std::string(value.kind_name());
    auto coefficient = [&]() {
      if (!value.is_number()) throw at_key(what + " must be a number, not " + value.kind_name());
      if (!(value.number >= 0 && value.number <= 1e6))
        throw at_key(what + " must be in [0, 1e+06] per metre, not " + value.text);
      return value.number;
    };
    if (key == "sigma_s") {
      f.sigma_s = coefficient();
    } else if (key == "sigma_a") {
      f.sigma_a = coefficient();
    } else if (key == "height_falloff") {
      f.height_falloff = coefficient();
    } else if (key == "g") {
      if (!value.is_number()) throw at_key(what + " must be a number, not " + value.kind_name());
      // Beyond ±g* Schlick's k = 1.55g − 0.55g³ leaves (−1, 1) and the phase function is no
      // longer a distribution (fog.h); g = ±1 itself is a delta.
      if (!(std::abs(value.number) < kFogMaxAbsG)) {
        char range[64];
        std::snprintf(range, sizeof range, "(-%.6f, %.6f)", kFogMaxAbsG, kFogMaxAbsG);
        throw at_key(what + " must be in " + range + ", where Schlick's k = 1.55g - 0.55g^3 stays inside (-1, 1), not " +
                     value.text);
      }
      f.g = value.number;
    } else if (key == "top") {
      if (!value.is_number()) throw at_key(what + " must be a number (world y, metres), not " + value.kind_name());
      if (!(value.number > ground_height)) {
        char ground[64];
        std::snprintf(ground, sizeof ground, "%g", ground_height);
        throw at_key(what + " " + value.text + " must be above the ground (ground.height " + ground + ")");
      }
      f.top = value.number;
    } else if (key == "mode") {
      const std::optional<FogMode> mode = value.is_string() ? fog_mode_from_name(value.text) : std::nullopt;
      if (!mode)
        throw at_key(what + " must be one of \"auto\", \"brute\", \"medium\", \"fast\", \"refined\", \"reference\", not " +
                     shown);
      f.mode = *mode;
    } else if (key == "steps") {
      const auto n = value.as_uint64();
      if (!n || *n == 0 || *n > kFogMaxSteps)
        throw at_key(what + " must be an integer from 1 to " + std::to_string(kFogMaxSteps) + ", not " + shown);
      f.steps = static_cast<uint32_t>(*n);
    } else if (key == "photons") {
      const auto n = value.as_uint64();
      if (!n || *n == 0 || *n > kFogMaxPhotons)
        throw at_key(what + " must be an integer from 1 to " + std::to_string(kFogMaxPhotons) + ", not " + shown);
      f.photons = *n;
    }
  }
  return f;
}

Scene read_scene(const JsonValue& root, const std::string& base_dir) {
  expect_object(root, "a scene");
  check_keys(root, "the scene",
             {"format", "version", "camera", "image", "sun", "sky", "ground", "fog", "materials", "plants"});
  Scene s;
  if (auto* x = root.find("format"); x && !(x->is_string() && x->text == "sylva-scene"))
    fail(*x, "format must be \"sylva-scene\"");
  if (auto* x = root.find("version"); x && x->as_uint64() != std::optional<uint64_t>(1))
    fail(*x, "unsupported scene version (this sylva reads version 1)");
  if (auto* x = root.find("camera")) s.camera = read_camera(*x);
  if (auto* x = root.find("image")) {
    expect_object(*x, "image");
    check_keys(*x, "image", {"width", "height"});
    if (auto* w = x->find("width")) s.width = image_size(*w, "image.width");
    if (auto* h = x->find("height")) s.height = image_size(*h, "image.height");
    if (auto problem = image_size_problem(s.width, s.height)) fail(*x, "image: " + *problem);
  }
  if (auto* x = root.find("sun")) s.sun = read_sun(*x);
  s.sun.direction = glm::normalize(s.sun.direction);
  if (auto* x = root.find("sky")) s.sky = colour(*x, "sky");
  if (auto* x = root.find("ground")) {
    expect_object(*x, "ground");
    check_keys(*x, "ground", {"height", "albedo"});
    if (auto* h = x->find("height")) s.ground.height = number(*h, "ground.height");
    if (auto* a = x->find("albedo")) s.ground.albedo = colour(*a, "ground.albedo");
  }
  if (auto* x = root.find("fog")) s.fog = read_fog(*x, s.ground.height);
  if (auto* x = root.find("materials")) s.materials = read_materials(*x);
  const JsonValue* plants = root.find("plants");
  if (!plants) fail(root, "a scene needs \"plants\" (an array of plants)");
  if (!plants->is_array()) fail(*plants, std::string("plants must be an array, not ") + plants->kind_name());
  for (size_t i = 0; i < plants->elements.size(); ++i)
    s.plants.push_back(read_plant(plants->elements[i], base_dir, i));
  return s;
}

}  // namespace

Expected<Scene> parse_scene_json(std::string_view text, std::string_view file, const std::string& base_dir) {
  Expected<JsonValue> json = parse_json(text, file);
  if (!json) return std::move(json.error());
  try {
    Scene scene = read_scene(*json, base_dir);
    scene.file = std::string(file);
    return scene;
  } catch (const Located& e) {
    return diagnostic_at(std::string(file), {e.line, e.column}, e.message);
  }
}

Expected<Scene> read_scene_file(const std::string& path) {
  Expected<std::string> file = read_text_file(path);
  if (!file) return std::move(file.error());
  return parse_scene_json(*file, path, std::filesystem::path(path).parent_path().string());
}

SkeletonBounds skeleton_bounds(const Skeleton& skeleton) {
  SkeletonBounds b;
  if (skeleton.joints.empty() && skeleton.leaves.empty()) return b;
  const double inf = std::numeric_limits<double>::infinity();
  b.lo = glm::dvec3(inf);
  b.hi = glm::dvec3(-inf);
  for (const Joint& j : skeleton.joints) {
    glm::dvec3 p(j.position_m[0], j.position_m[1], j.position_m[2]);
    b.lo = glm::min(b.lo, p - glm::dvec3(j.radius_m));
    b.hi = glm::max(b.hi, p + glm::dvec3(j.radius_m));
  }
  grow(b, leaf_bounds(skeleton));  // empty without leaves
  return b;
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

}  // namespace sylva

namespace sylva {

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

Status grow_scene_plants(Scene& scene, uint64_t max_modules, const Progress& progress) {
  size_t to_grow = 0, grown_so_far = 0;
  for (const ScenePlant& plant : scene.plants) to_grow += plant.skeleton ? 0 : 1;
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    ScenePlant& plant = scene.plants[i];
    if (plant.skeleton) continue;
    if (progress.cancelled()) return cancelled_diagnostic();
    // The grammar's own diagnostic, and where the scene named the grammar.
    auto located = [&](Diagnostic d) {
      if (d.cancelled) return d;
      Diagnostic note =
          diagnostic_at(scene.file, plant.grammar_loc, "plants[" + std::to_string(i) + "].grammar names this grammar");
      return std::move(d).with_note(std::move(note));
    };
    lsys::ParseOptions parse;
    parse.define_overrides = plant.defines;
    auto grammar = lsys::load_grammar(plant.grammar, parse);
    if (!grammar) return located(std::move(grammar.error()));
    lsys::DeriveOptions derive;
    derive.steps = plant.steps;
    derive.seed = plant.seed;
    derive.max_modules = max_modules;
    const double share = 1.0 / static_cast<double>(to_grow);
    derive.progress = progress.part(static_cast<double>(grown_so_far) * share,
                                    static_cast<double>(grown_so_far + 1) * share);
    auto grown = grow(*grammar, derive, plant.grammar, plant.defines);
    if (!grown) return located(std::move(grown.error()));
    plant.skeleton = std::move(grown->skeleton);
    ++grown_so_far;
  }
  for (size_t i = 0; i < scene.plants.size(); ++i) {
    const ScenePlant& plant = scene.plants[i];
    if (auto problem = plant_extent_problem(*plant.skeleton, plant.position, plant.scale))
      return diagnostic_at(scene.file, plant.grammar_loc, "plants[" + std::to_string(i) + "]: " + *problem);
  }
  progress.report(1, "grow");
  return {};
}

// ---------------------------------------------------------------------------------------
// Writing: one function per section, one line per key, in the order scene.md lists them,
// so that a new key is one line here beside its line in the reader above.

namespace {

using Layout = JsonWriter::Layout;

void write_vec3(JsonWriter& w, const glm::dvec3& v) {
  const double a[3] = {v.x, v.y, v.z};
  w.numbers(a, 3);
}

// `path` as a scene file in `base_dir` names it: relative to base_dir where reading it
// back (path_relative_to) gives exactly `path` again, so scenes stay movable; else an
// absolute path as stored, or the absolute form of a relative one.
std::string path_for_file(const std::string& path, const std::string& base_dir) {
  namespace fs = std::filesystem;
  const fs::path p(path), base(base_dir);
  if (base_dir.empty()) return path;
  if (p.is_absolute() == base.is_absolute()) {
    const fs::path relative = p.lexically_relative(base);
    if (!relative.empty() && !relative.is_absolute() && (base / relative).lexically_normal().string() == path)
      return relative.string();
  }
  return p.is_absolute() ? path : fs::absolute(p).lexically_normal().string();
}

void write_camera(JsonWriter& w, const Camera& c) {
  w.key("camera").begin_object(Layout::spaced);
  write_vec3(w.key("eye"), c.eye);
  write_vec3(w.key("target"), c.target);
  write_vec3(w.key("up"), c.up);
  w.key("fov_y_deg").number(c.fov_y_deg);
  w.end_object();
}

// The direction to write for the unit sun direction `unit`: the reader normalises what it
// reads (unit_sun_direction), and normalising is not idempotent in floating point, so
// `unit` itself may read back an ulp away. Of the vectors within 2 ulps
// of it per component, the first (in a fixed order, `unit` first) that reads back as
// exactly `unit` is written; in the unlikely case that none does, `unit` itself.
glm::dvec3 sun_direction_to_write(const glm::dvec3& unit) {
  auto read_back = [](const glm::dvec3& v) { return unit_sun_direction(v); };
  auto step = [](double x, int ulps) {
    for (; ulps > 0; --ulps) x = std::nextafter(x, std::numeric_limits<double>::infinity());
    for (; ulps < 0; ++ulps) x = std::nextafter(x, -std::numeric_limits<double>::infinity());
    return x;
  };
  constexpr int kOffsets[5] = {0, 1, -1, 2, -2};
  for (int dx : kOffsets)
    for (int dy : kOffsets)
      for (int dz : kOffsets) {
        const glm::dvec3 v(step(unit.x, dx), step(unit.y, dy), step(unit.z, dz));
        if (read_back(v) == unit) return v;
      }
  return unit;
}

void write_sun(JsonWriter& w, const Sun& s) {
  w.key("sun").begin_object(Layout::spaced);
  write_vec3(w.key("direction"), sun_direction_to_write(s.direction));
  w.key("angular_radius_deg").number(s.angular_radius_deg);
  write_vec3(w.key("radiance"), s.radiance);
  w.end_object();
}

void write_ground(JsonWriter& w, const Ground& g) {
  w.key("ground").begin_object(Layout::spaced);
  w.key("height").number(g.height);
  write_vec3(w.key("albedo"), g.albedo);
  w.end_object();
}

void write_fog(JsonWriter& w, const Fog& f) {
  w.key("fog").begin_object(Layout::spaced);
  w.key("sigma_s").number(f.sigma_s);
  w.key("sigma_a").number(f.sigma_a);
  w.key("g").number(f.g);
  w.key("height_falloff").number(f.height_falloff);
  if (std::isfinite(f.top)) w.key("top").number(f.top);  // +inf: no ceiling, no key
  w.key("mode").string(fog_mode_name(f.mode));
  w.key("steps").integer(f.steps);
  w.key("photons").integer(f.photons);
  w.end_object();
}

void write_bark(JsonWriter& w, const Bark& b, const std::string& base_dir) {
  w.key("bark").begin_object(Layout::spaced);
  if (b.albedo_texture) w.key("albedo").string(path_for_file(*b.albedo_texture, base_dir));
  else if (b.albedo_rgb) write_vec3(w.key("albedo"), *b.albedo_rgb);
  if (b.height_texture) w.key("height").string(path_for_file(*b.height_texture, base_dir));
  w.key("relief_depth").number(b.relief_depth_m);
  w.key("u_repeat").number(b.u_repeat);
  w.key("v_per_metre").number(b.v_per_metre);
  w.end_object();
}

void write_materials(JsonWriter& w, const std::map<uint32_t, SceneMaterial>& table) {
  w.key("materials").begin_array(Layout::lines);
  for (const auto& [index, m] : table) {
    w.begin_object(Layout::spaced);
    w.key("index").integer(index);
    if (m.albedo_rgb) write_vec3(w.key("albedo"), *m.albedo_rgb);
    w.key("specular").number(m.specular);
    w.end_object();
  }
  w.end_array();
}

void write_plant(JsonWriter& w, const ScenePlant& p, const std::string& base_dir) {
  w.begin_object(Layout::spaced);
  w.key("grammar").string(path_for_file(p.grammar, base_dir));
  if (p.seed) w.key("seed").integer(*p.seed);
  if (p.steps) w.key("steps").integer(*p.steps);
  w.key("defines").begin_object(Layout::spaced);
  for (const auto& [name, value] : p.defines) w.key(name).number(value);
  w.end_object();
  write_vec3(w.key("position"), p.position);
  w.key("rotate_y_deg").number(p.rotate_y_deg);
  w.key("scale").number(p.scale);
  write_bark(w, p.bark, base_dir);
  w.end_object();
}

}  // namespace

glm::dvec3 unit_sun_direction(const glm::dvec3& toward_sun) {
  // read_sun normalises what it reads, and read_scene normalises sun.direction once more.
  return glm::normalize(glm::normalize(toward_sun));
}

Expected<std::string> write_scene_json(const Scene& scene, const std::string& base_dir) {
  for (size_t i = 0; i < scene.plants.size(); ++i)
    if (scene.plants[i].grammar.empty())
      return file_diagnostic(scene.file, "plants[" + std::to_string(i) +
                                             "] has no grammar; a scene file names each plant's grammar");
  JsonWriter w;
  w.begin_object(Layout::lines);
  w.key("format").string("sylva-scene");
  w.key("version").integer(1);
  write_camera(w, scene.camera);
  w.key("image").begin_object(Layout::spaced);
  w.key("width").integer(scene.width);
  w.key("height").integer(scene.height);
  w.end_object();
  write_sun(w, scene.sun);
  write_vec3(w.key("sky"), scene.sky);
  write_ground(w, scene.ground);
  if (scene.fog) write_fog(w, *scene.fog);
  if (!scene.materials.empty()) write_materials(w, scene.materials);
  w.key("plants").begin_array(Layout::lines);
  for (const ScenePlant& plant : scene.plants) write_plant(w, plant, base_dir);
  w.end_array();
  w.end_object();
  return w.take() + "\n";
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

Skeleton place_plant(const ScenePlant& plant) {
  Skeleton sk = *plant.skeleton;
  const double angle = plant.rotate_y_deg * std::numbers::pi / 180;
  const double c = std::cos(angle), s = std::sin(angle);
  for (Joint& j : sk.joints) {
    const double x = plant.scale * j.position_m[0], y = plant.scale * j.position_m[1],
                 z = plant.scale * j.position_m[2];
    // R_y: x' = c x + s z, z' = −s x + c z (right-handed, counter-clockwise seen from +Y).
    j.position_m[0] = plant.position.x + c * x + s * z;
    j.position_m[1] = plant.position.y + y;
    j.position_m[2] = plant.position.z - s * x + c * z;
    j.radius_m *= plant.scale;
  }
  for (Leaf& leaf : sk.leaves)
    for (auto& v : leaf.vertices_m) {
      const double x = plant.scale * v[0], y = plant.scale * v[1], z = plant.scale * v[2];
      v = {plant.position.x + c * x + s * z, plant.position.y + y, plant.position.z - s * x + c * z};
    }
  return sk;
}

}  // namespace sylva
