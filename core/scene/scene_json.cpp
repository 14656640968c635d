// scene_json.cpp — reading docs/spec/scene.md's `.scene.json` (every key checked, errors at the
// offending key) and writing a scene back as one.
#include "core/scene/scene_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/geometry/leaf_mesh.h"
#include "core/light/fog.h"
#include "core/scene/materials.h"
#include "core/scene/scatter.h"
#include "core/util/diagnostic.h"
#include "core/util/file_io.h"
#include "core/util/image_io.h"
#include "core/util/json.h"
#include "core/util/limits.h"

namespace sylva {

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
  // The system would read the path only up to the NUL: another file, silently.
  if (v.text.find('\0') != std::string::npos)
    fail(v, std::string(what) + " must not hold a NUL character (\\u0000): no file name does");
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
  // The keys' own checks above give their places; what concerns them together, here.
  if (auto problem = camera_problem(c)) {
    if (problem->starts_with("eye and target")) fail(v, "camera.eye and camera.target must differ");
    fail(v, "camera." + *problem);
  }
  c.up = *rescaled_direction(c.up);
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
  const std::filesystem::file_type type = std::filesystem::status(path, ec).type();
  if (type != std::filesystem::file_type::regular) {
    // Say what is there instead: a directory or /dev/zero is not a missing file.
    using T = std::filesystem::file_type;
    const char* is = type == T::directory ? "a directory"
                     : type == T::character ? "a character device"
                     : type == T::block ? "a block device"
                     : type == T::fifo ? "a pipe"
                     : type == T::socket ? "a socket"
                     : nullptr;
    throw Located{line, column,
                  is ? what + ": '" + path + "' is " + is + ", not an image file"
                     : what + ": no such image file '" + path + "'"};
  }
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
std::map<uint32_t, SceneMaterial> read_materials(const JsonValue& v, const std::string& base_dir) {
  if (!v.is_array()) fail(v, std::string("materials must be an array, not ") + v.kind_name());
  std::map<uint32_t, SceneMaterial> table;
  for (size_t i = 0; i < v.elements.size(); ++i) {
    const JsonValue& e = v.elements[i];
    const std::string what = "materials[" + std::to_string(i) + "]";
    expect_object(e, what);
    check_keys(e, what, {"index", "albedo", "alpha", "specular", "two_sided", "u_repeat", "v_per_metre"});
    const JsonValue* index = e.find("index");
    if (!index) fail(e, what + " needs an \"index\" (the material index it describes)");
    const std::optional<uint64_t> k = index->as_uint64();
    if (!k || *k >= kMaterialSlots)
      fail(*index, what + ".index must be an integer from 0 to " + std::to_string(kMaterialSlots - 1));
    if (table.count(static_cast<uint32_t>(*k)))
      fail(*index, what + ".index " + std::to_string(*k) + " is described twice");
    SceneMaterial m;
    if (auto* x = e.find("albedo")) {
      if (x->is_array()) {
        m.albedo_rgb = colour(*x, what + ".albedo");
      } else {
        m.albedo_image = path_relative_to(base_dir, *x, what + ".albedo");
        check_texture(e, "albedo", *m.albedo_image, what + ".albedo");
      }
    }
    if (auto* x = e.find("alpha")) {
      m.alpha_image = path_relative_to(base_dir, *x, what + ".alpha");
      check_texture(e, "alpha", *m.alpha_image, what + ".alpha");
    }
    if (auto* x = e.find("specular")) m.specular = number_in(*x, what + ".specular", 0, 1, false, false);
    if (auto* x = e.find("two_sided")) {
      if (!x->is_bool()) fail(*x, what + ".two_sided must be true or false, not " + x->kind_name());
      m.two_sided = x->boolean;
    }
    for (const char* key : {"u_repeat", "v_per_metre"}) {
      const JsonValue* x = e.find(key);
      if (!x) continue;
      if (!m.albedo_image)
        fail(*x, what + "." + key + " lays an albedo image on the segments: give \"albedo\" an image file");
      if (!m.segment_repeat) m.segment_repeat.emplace();
      const double value = number_in(*x, what + "." + key, 0, 1e6, true, false);
      (std::string_view(key) == "u_repeat" ? m.segment_repeat->u_repeat : m.segment_repeat->v_per_metre) = value;
    }
    table.emplace(static_cast<uint32_t>(*k), m);
  }
  return table;
}

// What a plant and a scatter entry share: the grammar (required; its place kept for
// grow_scene_plants' note), the derivation steps and the #define overrides.
void read_recipe(const JsonValue& v, const std::string& base_dir, const std::string& what, std::string* grammar,
                 SourceLoc* grammar_loc, std::optional<int64_t>* steps, std::map<std::string, double>* defines) {
  const JsonValue* g = v.find("grammar");
  if (!g) fail(v, what + " needs a \"grammar\"");
  *grammar = path_relative_to(base_dir, *g, what + ".grammar");
  *grammar_loc = {g->line, g->column};
  if (auto* x = v.find("steps")) {
    auto n = x->as_uint64();
    if (!n || *n > 1000000) fail(*x, what + ".steps must be an integer from 0 to 1000000");
    *steps = static_cast<int64_t>(*n);
  }
  if (auto* x = v.find("defines")) {
    expect_object(*x, what + ".defines");
    for (const JsonMember& m : x->members) (*defines)[m.key.name] = number(m.value, what + ".defines." + m.key.name);
  }
}

// The `skin` key `v` (docs/spec/scene.md "Skin"), `otherwise` where there is none.
SkinStyle skin_style(const JsonValue* v, const std::string& what, SkinStyle otherwise) {
  if (!v) return otherwise;
  const std::optional<SkinStyle> style = v->is_string() ? parse_skin_style(v->text) : std::nullopt;
  if (!style) fail(*v, what + " must be \"smooth\" or \"paper\"");
  return *style;
}

ScenePlant read_plant(const JsonValue& v, const std::string& base_dir, size_t index, SkinStyle scene_skin) {
  const std::string what = "plants[" + std::to_string(index) + "]";
  expect_object(v, what);
  check_keys(v, what, {"grammar", "seed", "steps", "defines", "position", "rotate_y_deg", "scale", "bark", "skin"});
  ScenePlant p;
  read_recipe(v, base_dir, what, &p.grammar, &p.grammar_loc, &p.steps, &p.defines);
  if (auto* x = v.find("seed")) {
    auto s = x->as_uint64();
    if (!s) fail(*x, what + ".seed must be an integer from 0 to 18446744073709551615");
    p.seed = *s;
  }
  if (auto* x = v.find("position")) p.position = point(*x, what + ".position");
  if (auto* x = v.find("rotate_y_deg")) p.rotate_y_deg = number(*x, what + ".rotate_y_deg");
  if (auto* x = v.find("scale")) p.scale = number_in(*x, what + ".scale", 0, 1e9, true, false);
  if (auto* x = v.find("bark")) p.bark = read_bark(*x, base_dir, what + ".bark");
  p.skin = skin_style(v.find("skin"), what + ".skin", scene_skin);
  return p;
}

// A number or a [lo, hi] pair (lo <= hi), each in [min, max] (open at min when open_lo).
std::pair<double, double> number_or_range(const JsonValue& v, const std::string& what, double min, double max,
                                          bool open_lo) {
  if (v.is_array()) {
    if (v.elements.size() != 2) fail(v, what + " must be a number or [low, high]");
    const double a = number_in(v.elements[0], what, min, max, open_lo, false);
    const double b = number_in(v.elements[1], what, min, max, open_lo, false);
    if (a > b) fail(v, what + " [low, high] must have low <= high");
    return {a, b};
  }
  const double x = number_in(v, what, min, max, open_lo, false);
  return {x, x};
}

// A `scatter` entry (docs/scatter.md); its plants are placed by place_scatter.
SceneScatter read_scatter(const JsonValue& v, const std::string& base_dir, size_t index) {
  const std::string what = "scatter[" + std::to_string(index) + "]";
  expect_object(v, what);
  check_keys(v, what,
             {"grammar", "steps", "defines", "bark", "count", "density", "disc", "polygon", "seed", "plant_seeds",
              "rotate_y_deg", "scale", "min_spacing", "skin"});
  SceneScatter sc;
  read_recipe(v, base_dir, what, &sc.grammar, &sc.grammar_loc, &sc.steps, &sc.defines);
  if (auto* x = v.find("bark")) sc.bark = read_bark(*x, base_dir, what + ".bark");
  if (auto* x = v.find("skin")) sc.skin = skin_style(x, what + ".skin", SkinStyle::smooth);
  const JsonValue* disc = v.find("disc");
  const JsonValue* polygon = v.find("polygon");
  if ((disc != nullptr) == (polygon != nullptr)) fail(v, what + " needs exactly one area: \"disc\" or \"polygon\"");
  if (disc) {
    expect_object(*disc, what + ".disc");
    check_keys(*disc, what + ".disc", {"centre", "radius", "fade"});
    glm::dvec2 c(0, 0);
    if (auto* x = disc->find("centre")) {
      if (!x->is_array() || x->elements.size() != 2) fail(*x, what + ".disc.centre must be [x, z]");
      c = {number_in(x->elements[0], what + ".disc.centre", -kMaxCoordinateM, kMaxCoordinateM, false, false),
           number_in(x->elements[1], what + ".disc.centre", -kMaxCoordinateM, kMaxCoordinateM, false, false)};
    }
    sc.disc_centre = c;
    const JsonValue* r = disc->find("radius");
    if (!r) fail(*disc, what + ".disc needs a \"radius\"");
    sc.disc_radius = number_in(*r, what + ".disc.radius", 0, 1e9, true, false);
    if (auto* x = disc->find("fade"))
      sc.disc_fade = number_in(*x, what + ".disc.fade", 0, sc.disc_radius, false, false);
  } else {
    if (!polygon->is_array() || polygon->elements.size() < 3)
      fail(*polygon, what + ".polygon must be an array of at least 3 corners [x, z]");
    for (const JsonValue& corner : polygon->elements) {
      if (!corner.is_array() || corner.elements.size() != 2) fail(corner, what + ".polygon corners must be [x, z]");
      sc.polygon.push_back(
          {number_in(corner.elements[0], what + ".polygon", -kMaxCoordinateM, kMaxCoordinateM, false, false),
           number_in(corner.elements[1], what + ".polygon", -kMaxCoordinateM, kMaxCoordinateM, false, false)});
    }
    if (!(scatter_area_m2(sc) > 0)) fail(*polygon, what + ".polygon encloses no area");
  }
  const JsonValue* count = v.find("count");
  const JsonValue* density = v.find("density");
  if ((count != nullptr) == (density != nullptr)) fail(v, what + " needs exactly one of \"count\" and \"density\"");
  const std::string limit = std::to_string(kMaxScatterPlants);
  if (count) {
    auto n = count->as_uint64();
    if (!n || *n == 0 || *n > kMaxScatterPlants) fail(*count, what + ".count must be an integer from 1 to " + limit);
    sc.count = *n;
  } else {
    sc.density = number_in(*density, what + ".density", 0, 1e6, true, false);
    // Plants per m² where the rim does not fade them: the area weighted by the fade.
    const double area = scatter_weighted_area_m2(sc);
    const double n = std::round(*sc.density * area);
    if (!(n >= 1 && n <= static_cast<double>(kMaxScatterPlants)))
      fail(*density, what + ".density × the area's " + std::to_string(area) + " m^2" +
                         (sc.disc_fade > 0 ? " (its faded rim counted by its weight)" : "") + " must give 1 to " +
                         limit + " plants");
    sc.count = static_cast<uint64_t>(n);
  }
  if (auto* x = v.find("seed")) {
    auto n = x->as_uint64();
    if (!n) fail(*x, what + ".seed must be an integer from 0 to 18446744073709551615");
    sc.seed = *n;
  }
  if (auto* x = v.find("plant_seeds")) {
    const std::string expected = what + ".plant_seeds must be a seed or [first, last], integers from 0 to "
                                        "18446744073709551615 with first <= last";
    if (x->is_array()) {
      if (x->elements.size() != 2) fail(*x, expected);
      auto a = x->elements[0].as_uint64(), b = x->elements[1].as_uint64();
      if (!a || !b || *a > *b) fail(*x, expected);
      sc.plant_seeds = std::pair<uint64_t, uint64_t>{*a, *b};
    } else {
      auto a = x->as_uint64();
      if (!a) fail(*x, expected);
      sc.plant_seeds = std::pair<uint64_t, uint64_t>{*a, *a};
    }
  }
  if (auto* x = v.find("rotate_y_deg"))
    std::tie(sc.rotate_min_deg, sc.rotate_max_deg) = number_or_range(*x, what + ".rotate_y_deg", -1e6, 1e6, false);
  if (auto* x = v.find("scale")) std::tie(sc.scale_min, sc.scale_max) = number_or_range(*x, what + ".scale", 0, 1e9, true);
  if (auto* x = v.find("min_spacing")) sc.min_spacing = number_in(*x, what + ".min_spacing", 0, 1e9, false, false);
  return sc;
}

// The plants `scatter` (scene.scatter[index]) places on a ground at `ground_height`.
std::vector<ScenePlant> scatter_plants(const SceneScatter& sc, size_t index, double ground_height,
                                       const JsonValue& at) {
  const Expected<std::vector<ScatterPlacement>> placed = place_scatter(sc);
  if (!placed) fail(at, "scatter[" + std::to_string(index) + "]: " + placed.error().message);
  std::vector<ScenePlant> plants;
  for (const ScatterPlacement& pl : *placed) {
    ScenePlant p;
    p.grammar = sc.grammar;
    p.seed = pl.plant_seed;
    p.steps = sc.steps;
    p.defines = sc.defines;
    p.position = {pl.xz.x, ground_height, pl.xz.y};
    p.rotate_y_deg = pl.rotate_y_deg;
    p.scale = pl.scale;
    p.bark = sc.bark;
    p.grammar_loc = sc.grammar_loc;
    p.scatter = static_cast<uint32_t>(index + 1);
    plants.push_back(std::move(p));
  }
  return plants;
}

// The `fog` object (docs/spec/fog.md). Every key out of range is reported at the key (its line
// and column), so the message points at what to change.
Fog read_fog(const JsonValue& v, double ground_height) {
  expect_object(v, "fog");
  check_keys(v, "fog", {"sigma_s", "sigma_a", "g", "height_falloff", "top", "mode", "steps", "photons", "map_resolution",
                          "map_directions"});
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
        throw at_key(what + " must be one of \"auto\", \"brute\", \"medium\", \"fast\", \"refined\", \"reference\", \"map\", not " +
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
    } else if (key == "map_resolution") {
      const auto n = value.as_uint64();
      if (!n || *n < kFogMinMapResolution || *n > kFogMaxMapResolution || *n % 32 != 0)
        throw at_key(what + " must be a multiple of 32 from " + std::to_string(kFogMinMapResolution) + " to " +
                     std::to_string(kFogMaxMapResolution) + " (texels a side), not " + shown);
      f.map_resolution = static_cast<uint32_t>(*n);
    } else if (key == "map_directions") {
      const auto n = value.as_uint64();
      if (!n || *n == 0 || *n > kFogMaxMapDirections)
        throw at_key(what + " must be an integer from 1 to " + std::to_string(kFogMaxMapDirections) + ", not " + shown);
      f.map_directions = static_cast<uint32_t>(*n);
    }
  }
  return f;
}

// The `environment` object (docs/spec/light.md), each value out of range reported at its key.
LightEnvironment read_environment(const JsonValue& v) {
  expect_object(v, "environment");
  check_keys(v, "environment", {"sky", "sun_fraction", "photons", "sensor_radius_m", "every", "seed"});
  LightEnvironment e;
  for (const JsonMember& m : v.members) {
    const std::string& key = m.key.name;
    const JsonValue& value = m.value;
    const std::string what = "environment." + key;
    auto at_key = [&](const std::string& message) -> Located { return Located{m.key.line, m.key.column, message}; };
    const std::string shown = value.is_number()   ? value.text
                              : value.is_string() ? json_excerpt(value.text)
                                                  : std::string(value.kind_name());
    if (key == "sky") {
      const std::optional<LightSky> sky = value.is_string() ? light_sky_from_name(value.text) : std::nullopt;
      if (!sky)
        throw at_key(what + " must be one of \"sun\", \"uniform\", \"overcast\", \"sun+uniform\", \"sun+overcast\", not " +
                     shown);
      e.sky = *sky;
    } else if (key == "sun_fraction") {
      if (!value.is_number() || !(value.number >= 0 && value.number <= 1))
        throw at_key(what + " must be a number in [0, 1], not " + shown);
      e.sun_fraction = value.number;
    } else if (key == "photons") {
      const auto n = value.as_uint64();
      if (!n || *n == 0 || *n > kLightMaxPhotons)
        throw at_key(what + " must be an integer from 1 to " + std::to_string(kLightMaxPhotons) +
                     " (docs/limits.md), not " + shown);
      e.photons = *n;
    } else if (key == "sensor_radius_m") {
      if (!value.is_number() || !(value.number > 0 && value.number <= kLightMaxSensorRadiusM))
        throw at_key(what + " must be a number in (0, 1000] metres, not " + shown);
      e.sensor_radius_m = value.number;
    } else if (key == "every") {
      const auto n = value.as_uint64();
      if (!n || *n == 0 || *n > kLightMaxEvery)
        throw at_key(what + " must be an integer from 1 to " + std::to_string(kLightMaxEvery) + ", not " + shown);
      e.every = static_cast<uint32_t>(*n);
    } else if (key == "seed") {
      const auto n = value.as_uint64();
      if (!n) throw at_key(what + " must be a non-negative integer, not " + shown);
      e.seed = *n;
    }
  }
  return e;
}

// The `animation` object (docs/animation.md): `motion` first sets the defaults, then each
// key present replaces its own; every value out of range is reported at the value.
SceneAnimation read_animation(const JsonValue& v) {
  expect_object(v, "animation");
  check_keys(v, "animation",
             {"motion", "fps", "duration_s", "wind", "amplitude_deg", "frequency_hz", "branch_amplitude_deg",
              "branch_frequency_hz", "seed"});
  SceneAnimation a;
  if (auto* m = v.find("motion")) {
    if (!m->is_string() || (m->text != "sway" && m->text != "dance"))
      fail(*m, std::string("animation.motion must be \"sway\" or \"dance\", not ") +
                   (m->is_string() ? json_excerpt(m->text) : std::string(m->kind_name())));
    a = animation_defaults(m->text == "dance" ? AnimationMotion::dance : AnimationMotion::sway);
  }
  if (auto* x = v.find("fps")) a.fps = number_in(*x, "animation.fps", 0, 1000, true, false);
  if (auto* x = v.find("duration_s")) a.duration_s = number_in(*x, "animation.duration_s", 0, 1e6, true, false);
  if (auto* x = v.find("wind")) {
    a.wind = vec3(*x, "animation.wind");
    for (int k = 0; k < 3; ++k)
      if (!(std::abs(a.wind[k]) <= 1e6))
        fail(x->elements[k], "animation.wind components must be within ±1e6, not " + x->elements[k].text);
  }
  if (auto* x = v.find("amplitude_deg")) a.amplitude_deg = number_in(*x, "animation.amplitude_deg", 0, 90, false, false);
  if (auto* x = v.find("frequency_hz")) a.frequency_hz = number_in(*x, "animation.frequency_hz", 0, 100, false, false);
  if (auto* x = v.find("branch_amplitude_deg"))
    a.branch_amplitude_deg = number_in(*x, "animation.branch_amplitude_deg", 0, 90, false, false);
  if (auto* x = v.find("branch_frequency_hz"))
    a.branch_frequency_hz = number_in(*x, "animation.branch_frequency_hz", 0, 100, false, false);
  if (auto* x = v.find("seed")) {
    auto n = x->as_uint64();
    if (!n) fail(*x, "animation.seed must be an integer from 0 to 18446744073709551615");
    a.seed = *n;
  }
  if (!(a.duration_s * a.fps <= static_cast<double>(kMaxAnimationFrames)))
    fail(v, "animation: duration_s × fps asks for more than " + std::to_string(kMaxAnimationFrames) +
                " frames (docs/limits.md)");
  return a;
}

Scene read_scene(const JsonValue& root, const std::string& base_dir) {
  expect_object(root, "a scene");
  check_keys(root, "the scene",
             {"format", "version", "camera", "image", "sun", "sky", "ground", "fog", "environment", "animation",
              "materials", "plants", "scatter", "skin"});
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
  if (auto* x = root.find("environment")) s.environment = read_environment(*x);
  if (auto* x = root.find("animation")) s.animation = read_animation(*x);
  if (auto* x = root.find("materials")) s.materials = read_materials(*x, base_dir);
  s.skin = skin_style(root.find("skin"), "skin", SkinStyle::smooth);
  const JsonValue* plants = root.find("plants");
  if (!plants)
    fail(root, root.find("scatter") ? "a scene needs \"plants\" (docs/spec/scene.md), even where \"scatter\" places "
                                      "them all: add \"plants\": []"
                                    : "a scene needs \"plants\" (an array of plants)");
  if (!plants->is_array()) fail(*plants, std::string("plants must be an array, not ") + plants->kind_name());
  for (size_t i = 0; i < plants->elements.size(); ++i)
    s.plants.push_back(read_plant(plants->elements[i], base_dir, i, s.skin));
  if (auto* x = root.find("scatter")) {
    if (!x->is_array()) fail(*x, std::string("scatter must be an array, not ") + x->kind_name());
    for (size_t k = 0; k < x->elements.size(); ++k) {
      s.scatter.push_back(read_scatter(x->elements[k], base_dir, k));
      std::vector<ScenePlant> placed = scatter_plants(s.scatter.back(), k, s.ground.height, x->elements[k]);
      for (ScenePlant& p : placed) p.skin = s.scatter.back().skin.value_or(s.skin);
      if (s.plants.size() + placed.size() > kMaxScatterPlants)
        fail(x->elements[k], "the scene has more than " + std::to_string(kMaxScatterPlants) + " plants");
      s.plants.insert(s.plants.end(), std::make_move_iterator(placed.begin()), std::make_move_iterator(placed.end()));
    }
  }
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

Expected<SceneAnimation> parse_animation_json(std::string_view text, std::string_view file) {
  Expected<JsonValue> json = parse_json(text, file);
  if (!json) return std::move(json.error());
  try {
    return read_animation(*json);
  } catch (const Located& e) {
    return diagnostic_at(std::string(file), {e.line, e.column}, e.message);
  }
}

Expected<Scene> read_scene_file(const std::string& path) {
  Expected<std::string> file = read_text_file(path);
  if (!file) return std::move(file.error());
  return parse_scene_json(*file, path, std::filesystem::path(path).parent_path().string());
}

// ---------------------------------------------------------------------------------------
// Writing: one function per section, one line per key, in the order docs/spec/scene.md lists them,
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
  // The map's keys only where they differ from the defaults (scenes written before them
  // stay byte-identical).
  const Fog defaults;
  if (f.map_resolution != defaults.map_resolution) w.key("map_resolution").integer(f.map_resolution);
  if (f.map_directions != defaults.map_directions) w.key("map_directions").integer(f.map_directions);
  w.end_object();
}

void write_environment(JsonWriter& w, const LightEnvironment& e) {
  w.key("environment").begin_object(Layout::spaced);
  w.key("sky").string(light_sky_name(e.sky));
  w.key("sun_fraction").number(e.sun_fraction);
  w.key("photons").integer(e.photons);
  w.key("sensor_radius_m").number(e.sensor_radius_m);
  w.key("every").integer(e.every);
  w.key("seed").integer(e.seed);
  w.end_object();
}

void write_animation(JsonWriter& w, const SceneAnimation& a) {
  w.key("animation").begin_object(Layout::spaced);
  w.key("motion").string(animation_motion_name(a.motion));
  w.key("fps").number(a.fps);
  w.key("duration_s").number(a.duration_s);
  write_vec3(w.key("wind"), a.wind);
  w.key("amplitude_deg").number(a.amplitude_deg);
  w.key("frequency_hz").number(a.frequency_hz);
  w.key("branch_amplitude_deg").number(a.branch_amplitude_deg);
  w.key("branch_frequency_hz").number(a.branch_frequency_hz);
  w.key("seed").integer(a.seed);
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

void write_materials(JsonWriter& w, const std::map<uint32_t, SceneMaterial>& table, const std::string& base_dir) {
  w.key("materials").begin_array(Layout::lines);
  for (const auto& [index, m] : table) {
    w.begin_object(Layout::spaced);
    w.key("index").integer(index);
    if (m.albedo_rgb) write_vec3(w.key("albedo"), *m.albedo_rgb);
    if (m.albedo_image) w.key("albedo").string(path_for_file(*m.albedo_image, base_dir));
    if (m.alpha_image) w.key("alpha").string(path_for_file(*m.alpha_image, base_dir));
    w.key("specular").number(m.specular);
    if (!m.two_sided) w.key("two_sided").boolean(false);
    if (m.segment_repeat) {
      w.key("u_repeat").number(m.segment_repeat->u_repeat);
      w.key("v_per_metre").number(m.segment_repeat->v_per_metre);
    }
    w.end_object();
  }
  w.end_array();
}

// The keys read_recipe reads (and a plant's seed), in the order plants have always had them.
void write_recipe(JsonWriter& w, const std::string& grammar, std::optional<uint64_t> seed,
                  std::optional<int64_t> steps, const std::map<std::string, double>& defines,
                  const std::string& base_dir) {
  w.key("grammar").string(path_for_file(grammar, base_dir));
  if (seed) w.key("seed").integer(*seed);
  if (steps) w.key("steps").integer(*steps);
  w.key("defines").begin_object(Layout::spaced);
  for (const auto& [name, value] : defines) w.key(name).number(value);
  w.end_object();
}

void write_scatter(JsonWriter& w, const SceneScatter& sc, const std::string& base_dir) {
  w.begin_object(Layout::spaced);
  write_recipe(w, sc.grammar, std::nullopt, sc.steps, sc.defines, base_dir);
  if (sc.density) w.key("density").number(*sc.density);
  else w.key("count").integer(sc.count);
  if (sc.disc_centre) {
    w.key("disc").begin_object(Layout::spaced);
    const double c[2] = {sc.disc_centre->x, sc.disc_centre->y};
    w.key("centre").numbers(c, 2);
    w.key("radius").number(sc.disc_radius);
    if (sc.disc_fade > 0) w.key("fade").number(sc.disc_fade);
    w.end_object();
  } else {
    w.key("polygon").begin_array(Layout::spaced);
    for (const glm::dvec2& corner : sc.polygon) {
      const double c[2] = {corner.x, corner.y};
      w.numbers(c, 2);
    }
    w.end_array();
  }
  w.key("seed").integer(sc.seed);
  if (sc.plant_seeds) {
    w.key("plant_seeds").begin_array(Layout::spaced);
    w.integer(sc.plant_seeds->first).integer(sc.plant_seeds->second);
    w.end_array();
  }
  const double rotate[2] = {sc.rotate_min_deg, sc.rotate_max_deg}, scale[2] = {sc.scale_min, sc.scale_max};
  w.key("rotate_y_deg").numbers(rotate, 2);
  w.key("scale").numbers(scale, 2);
  w.key("min_spacing").number(sc.min_spacing);
  write_bark(w, sc.bark, base_dir);
  if (sc.skin) w.key("skin").string(skin_style_name(*sc.skin));
  w.end_object();
}

void write_plant(JsonWriter& w, const ScenePlant& p, const std::string& base_dir, SkinStyle scene_skin) {
  w.begin_object(Layout::spaced);
  write_recipe(w, p.grammar, p.seed, p.steps, p.defines, base_dir);
  write_vec3(w.key("position"), p.position);
  w.key("rotate_y_deg").number(p.rotate_y_deg);
  w.key("scale").number(p.scale);
  write_bark(w, p.bark, base_dir);
  if (p.skin != scene_skin) w.key("skin").string(skin_style_name(p.skin));
  w.end_object();
}

}  // namespace

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
  if (scene.environment) write_environment(w, *scene.environment);
  if (scene.animation) write_animation(w, *scene.animation);
  if (!scene.materials.empty()) write_materials(w, scene.materials, base_dir);
  if (scene.skin != SkinStyle::smooth) w.key("skin").string(skin_style_name(scene.skin));
  w.key("plants").begin_array(Layout::lines);
  for (const ScenePlant& plant : scene.plants)
    if (plant.scatter == 0) write_plant(w, plant, base_dir, scene.skin);  // scattered ones: their entry
  w.end_array();
  if (!scene.scatter.empty()) {
    w.key("scatter").begin_array(Layout::lines);
    for (const SceneScatter& sc : scene.scatter) write_scatter(w, sc, base_dir);
    w.end_array();
  }
  w.end_object();
  return w.take() + "\n";
}

}  // namespace sylva
