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
#include "core/util/file_io.h"
#include "core/util/json.h"
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

std::string SceneError::format() const {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
  return out + ": error: " + message;
}

namespace {

// Thrown inside this file only; parse_scene_json turns it into a SceneError.
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

glm::dvec3 colour(const JsonValue& v, std::string_view what) {
  glm::dvec3 c = vec3(v, what);
  for (int k = 0; k < 3; ++k)
    if (c[k] < 0) fail(v.elements[k], std::string(what) + " components must be >= 0");
  return c;
}

uint32_t image_size(const JsonValue& v, std::string_view what) {
  auto n = v.as_uint64();
  if (!n || *n == 0 || *n > 65536) fail(v, std::string(what) + " must be an integer from 1 to 65536");
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
  if (auto* x = v.find("eye")) c.eye = vec3(*x, "camera.eye");
  if (auto* x = v.find("target")) c.target = vec3(*x, "camera.target");
  if (auto* x = v.find("up")) c.up = vec3(*x, "camera.up");
  if (auto* x = v.find("fov_y_deg")) c.fov_y_deg = number_in(*x, "camera.fov_y_deg", 0, 180, true, true);
  glm::dvec3 forward = c.target - c.eye;
  if (!(glm::length(forward) > 0)) fail(v, "camera.eye and camera.target must differ");
  glm::dvec3 side = glm::cross(forward, c.up);
  if (!(glm::length(side) > 1e-9 * glm::length(forward) * glm::length(c.up)))
    fail(v, "camera.up must not be parallel to the view direction (or zero)");
  return c;
}

Sun read_sun(const JsonValue& v) {
  expect_object(v, "sun");
  check_keys(v, "sun", {"direction", "angular_radius_deg", "radiance"});
  Sun s;
  if (auto* x = v.find("direction")) {
    s.direction = vec3(*x, "sun.direction");
    if (!(glm::length(s.direction) > 0)) fail(*x, "sun.direction must not be zero");
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
  if (auto reason = image_open_error(path))
    throw Located{line, column, what + ": cannot open image '" + path + "': " + *reason};
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

ScenePlant read_plant(const JsonValue& v, const std::string& base_dir, size_t index) {
  const std::string what = "plants[" + std::to_string(index) + "]";
  expect_object(v, what);
  check_keys(v, what, {"grammar", "seed", "steps", "defines", "position", "rotate_y_deg", "scale", "bark"});
  ScenePlant p;
  const JsonValue* g = v.find("grammar");
  if (!g) fail(v, what + " needs a \"grammar\"");
  p.grammar = path_relative_to(base_dir, *g, what + ".grammar");
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
  if (auto* x = v.find("position")) p.position = vec3(*x, what + ".position");
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
             {"format", "version", "camera", "image", "sun", "sky", "ground", "fog", "plants"});
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
  const JsonValue* plants = root.find("plants");
  if (!plants) fail(root, "a scene needs \"plants\" (an array of plants)");
  if (!plants->is_array()) fail(*plants, std::string("plants must be an array, not ") + plants->kind_name());
  for (size_t i = 0; i < plants->elements.size(); ++i)
    s.plants.push_back(read_plant(plants->elements[i], base_dir, i));
  return s;
}

}  // namespace

SceneReadResult parse_scene_json(std::string_view text, std::string_view file,
                                 const std::string& base_dir) {
  SceneReadResult result;
  JsonParseResult json = parse_json(text);
  if (json.error) {
    result.error = SceneError{std::string(file), json.error->line, json.error->column, json.error->message};
    return result;
  }
  try {
    result.scene = read_scene(*json.value, base_dir);
  } catch (const Located& e) {
    result.error = SceneError{std::string(file), e.line, e.column, e.message};
  }
  return result;
}

SceneReadResult read_scene_file(const std::string& path) {
  FileReadResult file = read_text_file(path);
  if (file.error) {
    SceneReadResult r;
    r.error = SceneError{path, 0, 0, file.error->message};
    return r;
  }
  return parse_scene_json(*file.contents, path, std::filesystem::path(path).parent_path().string());
}

SkeletonBounds skeleton_bounds(const Skeleton& skeleton) {
  SkeletonBounds b;
  if (skeleton.joints.empty()) return b;
  const double inf = std::numeric_limits<double>::infinity();
  b.lo = glm::dvec3(inf);
  b.hi = glm::dvec3(-inf);
  for (const Joint& j : skeleton.joints) {
    glm::dvec3 p(j.position_m[0], j.position_m[1], j.position_m[2]);
    b.lo = glm::min(b.lo, p - glm::dvec3(j.radius_m));
    b.hi = glm::max(b.hi, p + glm::dvec3(j.radius_m));
  }
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

std::optional<std::string> grow_scene_plants(Scene& scene, uint64_t max_modules) {
  for (ScenePlant& plant : scene.plants) {
    if (plant.skeleton) continue;
    lsys::ParseOptions parse;
    parse.define_overrides = plant.defines;
    auto grammar = lsys::load_grammar(plant.grammar, parse);
    if (!grammar) return grammar.error().format();
    lsys::DeriveOptions derive;
    derive.steps = plant.steps;
    derive.seed = plant.seed;
    derive.max_modules = max_modules;
    auto grown = grow(*grammar, derive, plant.grammar, plant.defines);
    if (!grown) return grown.error().format();
    plant.skeleton = std::move(grown->skeleton);
  }
  return std::nullopt;
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
  return sk;
}

}  // namespace sylva
