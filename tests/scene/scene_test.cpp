// scene_test.cpp — docs/spec/scene.md's scene files: every key read, defaults, located errors, a
// plant's grammar error named at its scene key, and write_scene_json read back equal.
#include "core/scene/scene.h"
#include "core/scene/materials.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <random>
#include <set>

#include "core/scene/render_common.h"
#include "core/scene/scatter.h"
#include "core/scene/scene_json.h"
#include "tests/support/test_textures.h"

namespace sylva {

// Failures show a scene as the text write_scene_json makes of it, and its places.
void PrintTo(const Scene& s, std::ostream* os) {
  Expected<std::string> text = write_scene_json(s);
  *os << (text ? *text : text.error().format()) << "(file \"" << s.file << "\")";
}

namespace {

const char* const kExample = R"({
  "format": "sylva-scene", "version": 1,
  "camera": {"eye": [6, 3, 6], "target": [0, 2, 0], "up": [0, 1, 0], "fov_y_deg": 40},
  "image": {"width": 640, "height": 480},
  "sun": {"direction": [0, 2, 0], "angular_radius_deg": 0.27, "radiance": [3, 3, 2.8]},
  "sky": [0.25, 0.3, 0.4],
  "ground": {"height": -1, "albedo": [0.35, 0.3, 0.25]},
  "fog": {"sigma_s": 0.05, "sigma_a": 0.005, "g": 0.6, "height_falloff": 0.0},
  "plants": [
    {"grammar": "presets/saguaro.lsys", "seed": 3, "steps": 6, "defines": {"N": 5},
     "position": [1, 0, 2], "rotate_y_deg": 90, "scale": 2,
     "bark": {"albedo": "textures/bark.png", "height": "textures/bark_height.png",
              "relief_depth": 0.02, "u_repeat": 2, "v_per_metre": 1}}
  ]
})";

Diagnostic expect_error(std::string_view text) {
  Expected<Scene> r = parse_scene_json(text, "s.scene.json", "");
  EXPECT_FALSE(r.ok());
  return r ? Diagnostic{} : r.error();
}

TEST(Scene, ReadsEveryKeyOfTheSpecExample) {
  // The example's textures must exist and open (they are checked when the scene is read).
  test::TempFolder dir;
  std::filesystem::create_directories(dir.file("textures"));
  test::write_rgb_png(dir.file("textures/bark.png"), 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{}; });
  test::write_rgb_png(dir.file("textures/bark_height.png"), 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{}; });
  Expected<Scene> r = parse_scene_json(kExample, "dir/a.scene.json", dir.path());
  ASSERT_TRUE(r.ok()) << r.error().format();
  const Scene& s = *r;
  EXPECT_EQ(s.camera.eye, glm::dvec3(6, 3, 6));
  EXPECT_EQ(s.camera.target, glm::dvec3(0, 2, 0));
  EXPECT_EQ(s.camera.fov_y_deg, 40);
  EXPECT_EQ(s.width, 640u);
  EXPECT_EQ(s.height, 480u);
  EXPECT_EQ(s.sun.direction, glm::dvec3(0, 1, 0));  // stored unit
  EXPECT_EQ(s.sun.angular_radius_deg, 0.27);
  EXPECT_EQ(s.sun.radiance, glm::dvec3(3, 3, 2.8));
  EXPECT_EQ(s.sky, glm::dvec3(0.25, 0.3, 0.4));
  EXPECT_EQ(s.ground.height, -1);
  ASSERT_TRUE(s.fog);
  EXPECT_EQ(s.fog->g, 0.6);
  ASSERT_EQ(s.plants.size(), 1u);
  const ScenePlant& p = s.plants[0];
  EXPECT_EQ(p.grammar, dir.file("presets/saguaro.lsys"));  // relative to the scene file
  EXPECT_EQ(p.seed, 3u);
  EXPECT_EQ(p.steps, 6);
  EXPECT_EQ(p.defines.at("N"), 5);
  EXPECT_EQ(p.position, glm::dvec3(1, 0, 2));
  EXPECT_EQ(p.rotate_y_deg, 90);
  EXPECT_EQ(p.scale, 2);
  EXPECT_EQ(p.bark.albedo_texture, dir.file("textures/bark.png"));
  EXPECT_EQ(p.bark.height_texture, dir.file("textures/bark_height.png"));
  EXPECT_EQ(p.bark.u_repeat, 2);
}

TEST(Scene, BarkTextureThatDoesNotExistOrOpenIsAnErrorAtItsKey) {
  test::TempFolder dir;
  Expected<Scene> r = parse_scene_json(
      "{\"plants\": [{\"grammar\": \"g.lsys\",\n  \"bark\": {\"u_repeat\": 2,\n   \"albedo\": \"nope.png\"}}]}",
      "s.scene.json", dir.path());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().loc.line, 3u);
  EXPECT_EQ(r.error().loc.column, 4u);
  EXPECT_NE(r.error().message.find("plants[0].bark.albedo"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find(dir.file("nope.png")), std::string::npos) << r.error().message;
  // A file OpenImageIO cannot read, as the height map.
  {
    std::ofstream out(dir.file("text.png"));
    out << "not an image";
  }
  r = parse_scene_json("{\"plants\": [{\"grammar\": \"g.lsys\", \"bark\": {\"height\": \"text.png\"}}]}",
                       "s.scene.json", dir.path());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().loc.line, 1u);
  EXPECT_EQ(r.error().loc.column, 44u);
  EXPECT_NE(r.error().message.find("plants[0].bark.height: cannot open image"), std::string::npos) << r.error().message;
}

TEST(Scene, OnlyPlantsIsRequiredAndTheRestDefaults) {
  Expected<Scene> r = parse_scene_json(R"({"plants": [{"grammar": "g.lsys"}]})", "s", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_EQ(r->width, 1024u);
  EXPECT_EQ(r->height, 768u);
  EXPECT_FALSE(r->fog);  // no fog key, no fog pass
  EXPECT_NEAR(glm::length(r->sun.direction), 1.0, 1e-15);
  EXPECT_EQ(r->plants[0].scale, 1);
  EXPECT_FALSE(r->plants[0].seed);
}

TEST(Scene, UnknownTopLevelKeyNamesKeyFileLineAndColumn) {
  Diagnostic e = expect_error("{\"plants\": [],\n  \"camra\": {}}");
  EXPECT_EQ(e.loc.line, 2u);
  EXPECT_EQ(e.loc.column, 3u);
  EXPECT_NE(e.message.find("\"camra\""), std::string::npos) << e.message;
  EXPECT_EQ(e.format().rfind("s.scene.json:2:3: error: unknown key \"camra\"", 0), 0u) << e.format();
}

TEST(Scene, UnknownNestedKeyIsLocatedAtTheKey) {
  Diagnostic e = expect_error("{\"plants\": [{\"grammar\": \"g.lsys\",\n    \"bark\": {\"u_repeet\": 2}}]}");
  EXPECT_EQ(e.loc.line, 2u);
  EXPECT_EQ(e.loc.column, 14u);
  EXPECT_NE(e.message.find("u_repeet"), std::string::npos);
  EXPECT_NE(e.message.find("plants[0].bark"), std::string::npos) << e.message;
}

// "plant.lsys\u0000.missing" would open plant.lsys (issue 32): refused at the key.
TEST(Scene, APathHoldingANulIsAnErrorAtItsKey) {
  Diagnostic e = expect_error("{\"plants\": [{\"grammar\":\n  \"plant.lsys\\u0000.missing\"}]}");
  EXPECT_EQ(e.loc.line, 2u) << e.format();
  EXPECT_NE(e.message.find("NUL"), std::string::npos) << e.format();
  EXPECT_NE(e.message.find("grammar"), std::string::npos) << e.format();
}

TEST(Scene, MissingPlantsIsAnError) {
  Diagnostic e = expect_error("{\"sky\": [1, 1, 1]}");
  EXPECT_NE(e.message.find("plants"), std::string::npos);
  // Only scatter: the contract still wants the key, and the message says what to write.
  e = expect_error("{\"scatter\": []}");
  EXPECT_NE(e.message.find("even where \"scatter\" places them all: add \"plants\": []"), std::string::npos)
      << e.message;
}

TEST(Scene, WrongTypesAndRangesAreLocated) {
  Diagnostic e = expect_error("{\"plants\": [],\n \"camera\": {\"fov_y_deg\": 180}}");
  EXPECT_EQ(e.loc.line, 2u);
  EXPECT_EQ(e.loc.column, 26u);
  e = expect_error("{\"plants\": [], \"image\": {\"width\": 1.5}}");
  EXPECT_NE(e.message.find("image.width"), std::string::npos);
  e = expect_error("{\"plants\": [], \"sky\": [1, 2]}");
  EXPECT_NE(e.message.find("sky"), std::string::npos);
  e = expect_error("{\"plants\": [{\"seed\": 1}]}");
  EXPECT_NE(e.message.find("grammar"), std::string::npos);
  e = expect_error("{\"plants\": [], \"camera\": {\"eye\": [0, 1, 0], \"target\": [0, 5, 0]}}");
  EXPECT_NE(e.message.find("parallel"), std::string::npos);
  e = expect_error("{\"plants\": [], \"version\": 2}");
  EXPECT_NE(e.message.find("version"), std::string::npos);
}

TEST(SceneFog, ReadsEveryFogKeyOfTheSpec) {
  // docs/spec/fog.md's example.
  Expected<Scene> r = parse_scene_json(R"({"plants": [],
    "fog": {"sigma_s": 0.05, "sigma_a": 0.005, "g": 0.6, "height_falloff": 0.0, "top": 30,
            "mode": "auto", "steps": 64, "photons": 1000000}})",
                                       "s", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  const Fog& f = *r->fog;
  EXPECT_EQ(f.sigma_s, 0.05);
  EXPECT_EQ(f.sigma_a, 0.005);
  EXPECT_EQ(f.g, 0.6);
  EXPECT_EQ(f.height_falloff, 0.0);
  EXPECT_EQ(f.top, 30);
  EXPECT_EQ(f.mode, FogMode::automatic);
  EXPECT_EQ(f.steps, 64u);
  EXPECT_EQ(f.photons, 1000000u);
  r = parse_scene_json(R"({"plants": [], "fog": {"mode": "reference", "steps": 7, "photons": 12, "top": -0.5,
                           "height_falloff": 0.3}, "ground": {"height": -1}})",
                       "s", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_EQ(r->fog->mode, FogMode::reference);
  EXPECT_EQ(r->fog->steps, 7u);
  EXPECT_EQ(r->fog->photons, 12u);
  EXPECT_EQ(r->fog->top, -0.5);  // above a ground at -1
  EXPECT_EQ(r->fog->height_falloff, 0.3);
}

TEST(SceneFog, AbsentKeysDefault) {
  Expected<Scene> r = parse_scene_json(R"({"plants": [], "fog": {}})", "s", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  const Fog& f = *r->fog;
  EXPECT_TRUE(std::isinf(f.top));  // no ceiling
  EXPECT_EQ(f.mode, FogMode::automatic);
  EXPECT_EQ(f.steps, 64u);
  EXPECT_EQ(f.photons, 1000000u);
  EXPECT_EQ(f.sigma_s, 0.05);
  EXPECT_EQ(f.map_resolution, 2048u);
  EXPECT_EQ(f.map_directions, 4u);
}

TEST(SceneFog, MapKeysAreReadAndWrittenOnlyWhereTheyDifferFromTheDefaults) {
  Expected<Scene> r = parse_scene_json(
      R"({"plants": [], "fog": {"mode": "map", "map_resolution": 4096, "map_directions": 9}})", "s", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_EQ(r->fog->mode, FogMode::map);
  EXPECT_EQ(r->fog->map_resolution, 4096u);
  EXPECT_EQ(r->fog->map_directions, 9u);
  const Expected<std::string> text = write_scene_json(*r);
  ASSERT_TRUE(text.ok()) << text.error().format();
  const std::string& written = *text;
  EXPECT_NE(written.find("\"map_resolution\": 4096"), std::string::npos) << written;
  EXPECT_NE(written.find("\"map_directions\": 9"), std::string::npos) << written;
  Scene plain = *r;
  plain.fog = Fog{};
  const Expected<std::string> plain_text = write_scene_json(plain);
  ASSERT_TRUE(plain_text.ok()) << plain_text.error().format();
  EXPECT_EQ(plain_text->find("map_"), std::string::npos);
}

TEST(SceneFog, ModeNamesRoundTrip) {
  for (FogMode m : {FogMode::automatic, FogMode::brute, FogMode::medium, FogMode::fast, FogMode::refined,
                    FogMode::reference, FogMode::map})
    EXPECT_EQ(fog_mode_from_name(fog_mode_name(m)), m);
  EXPECT_EQ(fog_mode_name(FogMode::map), std::string("map"));
  EXPECT_EQ(fog_mode_name(FogMode::automatic), std::string("auto"));
  EXPECT_FALSE(fog_mode_from_name("automatic"));
  EXPECT_FALSE(fog_mode_from_name("Brute"));
}

TEST(SceneFog, EveryKeyOutOfRangeIsAnErrorAtTheKey) {
  struct Bad {
    const char* member;  // the fog object's one member
    const char* says;    // part of the message
  };
  const Bad bad[] = {
      {R"("sigma_s": -0.1)", "fog.sigma_s must be in [0, 1e+06]"},
      {R"("sigma_a": -1e-9)", "fog.sigma_a must be in [0, 1e+06]"},
      {R"("sigma_s": 2e6)", "fog.sigma_s must be in [0, 1e+06]"},
      {R"("height_falloff": -1)", "fog.height_falloff must be in [0, 1e+06]"},
      {R"("sigma_s": "thick")", "fog.sigma_s must be a number, not a string"},
      {R"("sigma_a": null)", "fog.sigma_a must be a number, not null"},
      {R"("g": 1)", "fog.g must be in (-0.938117, 0.938117)"},
      {R"("g": -1)", "fog.g must be in (-0.938117, 0.938117)"},
      {R"("g": 0.95)", "where Schlick's k"},  // |g| < 1 but |k| > 1
      {R"("g": [0.5])", "fog.g must be a number, not an array"},
      {R"("top": -3)", "fog.top -3 must be above the ground (ground.height 0)"},
      {R"("top": 0)", "must be above the ground"},
      {R"("top": "high")", "fog.top must be a number"},
      {R"("mode": "fastest")", R"(fog.mode must be one of "auto", "brute", "medium", "fast", "refined", "reference", "map", not "fastest")"},
      {R"("mode": 3)", "fog.mode must be one of"},
      {R"("steps": 0)", "fog.steps must be an integer from 1 to 65536, not 0"},
      {R"("steps": 1.5)", "fog.steps must be an integer from 1 to 65536, not 1.5"},
      {R"("steps": 65537)", "not 65537"},
      {R"("steps": -4)", "not -4"},
      {R"("steps": "64")", "fog.steps must be an integer from 1 to 65536, not \"64\""},
      {R"("photons": 0)", "fog.photons must be an integer from 1 to 1000000000, not 0"},
      {R"("photons": 2e9)", "not 2e9"},
      {R"("photons": true)", "not a boolean"},
      {R"("map_resolution": 1000)", "fog.map_resolution must be a multiple of 32 from 32 to 65536 (texels a side), not 1000"},
      {R"("map_resolution": 0)", "not 0"},
      {R"("map_resolution": 131072)", "not 131072"},
      {R"("map_resolution": 2048.5)", "not 2048.5"},
      {R"("map_directions": 0)", "fog.map_directions must be an integer from 1 to 64, not 0"},
      {R"("map_directions": 65)", "not 65"},
      {R"("densty": 1)", "unknown key \"densty\" in fog"},
  };
  for (const Bad& b : bad) {
    // The fog object's key starts at line 2, column 10.
    const std::string text = std::string("{\"plants\": [],\n \"fog\": {") + b.member + "}}";
    Diagnostic e = expect_error(text);
    EXPECT_EQ(e.loc.line, 2u) << b.member;
    EXPECT_EQ(e.loc.column, 10u) << b.member;
    EXPECT_NE(e.message.find(b.says), std::string::npos) << b.member << ": " << e.message;
    EXPECT_EQ(e.format().rfind("s.scene.json:2:10: error: ", 0), 0u) << e.format();
  }
  // The top is compared with the ground wherever the ground key stands.
  Diagnostic e = expect_error("{\"fog\": {\"top\": 4},\n \"ground\": {\"height\": 5}, \"plants\": []}");
  EXPECT_EQ(e.loc.line, 1u);
  EXPECT_EQ(e.loc.column, 10u);
  EXPECT_NE(e.message.find("fog.top 4 must be above the ground (ground.height 5)"), std::string::npos) << e.message;
}

TEST(SceneMaterials, ReadsTheTableOfDocsMaterialsMd) {
  Expected<Scene> s = parse_scene_json(R"({"plants": [], "materials": [
      {"index": 1, "albedo": [0.05, 0.22, 0.06], "specular": 0.4},
      {"index": 3, "albedo": [0.9, 0.8, 0.2]},
      {"index": 0, "specular": 0}]})",
                                       "m.scene.json", "");
  ASSERT_TRUE(s.ok()) << s.error().format();
  ASSERT_EQ(s->materials.size(), 3u);
  EXPECT_EQ(s->materials.at(1), (SceneMaterial{glm::dvec3(0.05, 0.22, 0.06), 0.4}));
  EXPECT_EQ(s->materials.at(3), (SceneMaterial{glm::dvec3(0.9, 0.8, 0.2), 1}));
  EXPECT_EQ(s->materials.at(0), (SceneMaterial{std::nullopt, 0}));
}

TEST(SceneMaterials, TheBarkColourComesFirstOnWoodThenTheTableThenTheDefaults) {
  std::map<uint32_t, SceneMaterial> table{{0, {glm::dvec3(0.5, 0.5, 0.5), 0.25}}, {2, {glm::dvec3(0.1, 0.2, 0.3), 1}},
                                          {5, {std::nullopt, 0.5}}};
  Bark bark;
  bark.albedo_rgb = glm::dvec3(0.7, 0.1, 0.1);
  const double* d1 = default_material_albedo(1);
  const double* d5 = default_material_albedo(5);
  EXPECT_EQ(material_look(table, &bark, 0).albedo, glm::dvec3(0.7, 0.1, 0.1));
  EXPECT_EQ(material_look(table, &bark, 0).specular, 0.25);
  EXPECT_EQ(material_look(table, nullptr, 0).albedo, glm::dvec3(0.5, 0.5, 0.5));
  EXPECT_EQ(material_look(table, &bark, 2).albedo, glm::dvec3(0.1, 0.2, 0.3));  // the bark is the wood's only
  EXPECT_EQ(material_look(table, &bark, 1).albedo, glm::dvec3(d1[0], d1[1], d1[2]));
  EXPECT_EQ(material_look(table, &bark, 1).specular, 1);
  EXPECT_EQ(material_look(table, &bark, 5).albedo, glm::dvec3(d5[0], d5[1], d5[2]));
  EXPECT_EQ(material_look(table, &bark, 5).specular, 0.5);
}

TEST(SceneMaterials, EveryBadEntryIsAnErrorAtItsKey) {
  struct Bad {
    const char* entry;  // the table's one entry
    const char* says;
    uint32_t column;    // where the error points (the entry starts at column 16)
  };
  const Bad bad[] = {
      {R"({"albedo": [1, 1, 1]})", "materials[0] needs an \"index\"", 16},
      {R"({"index": 256})", "materials[0].index must be an integer from 0 to 255", 26},
      {R"({"index": -1})", "materials[0].index must be an integer from 0 to 255", 26},
      {R"({"index": 1.5})", "materials[0].index must be an integer", 26},
      {R"({"index": 1, "specular": 1.5})", "materials[0].specular must be in [0, 1]", 41},
      {R"({"index": 1, "albedo": [1, -1, 1]})", "materials[0].albedo components must be >= 0", 43},
      {R"({"index": 1, "albedo": "leaf.png"})", "materials[0].albedo: no such image file", 29},
      {R"({"index": 1, "alpha": "mask.png"})", "materials[0].alpha: no such image file", 29},
      // Something that is there but is no image is named for what it is.
      {R"({"index": 1, "albedo": "/dev/zero"})", "materials[0].albedo: '/dev/zero' is a character device, not an image file", 29},
      {R"({"index": 1, "albedo": "/tmp"})", "materials[0].albedo: '/tmp' is a directory, not an image file", 29},
      {R"({"index": 1, "albedo": 7})", "materials[0].albedo", 39},
      {R"({"index": 1, "two_sided": 1})", "materials[0].two_sided must be true or false", 42},
      {R"({"index": 1, "colour": [1, 1, 1]})", "unknown key \"colour\" in materials[0]", 29},
      {R"(7)", "materials[0] must be an object", 16},
  };
  for (const Bad& b : bad) {
    const std::string text = std::string("{\"plants\": [],\n \"materials\": [") + b.entry + "]}";
    Diagnostic e = expect_error(text);
    EXPECT_EQ(e.loc.line, 2u) << b.entry;
    EXPECT_EQ(e.loc.column, b.column) << b.entry << ": " << e.message;
    EXPECT_NE(e.message.find(b.says), std::string::npos) << b.entry << ": " << e.message;
  }
  Diagnostic e = expect_error("{\"plants\": [], \"materials\": [{\"index\": 2},\n {\"index\": 2}]}");
  EXPECT_EQ(e.loc.line, 2u);
  EXPECT_NE(e.message.find("materials[1].index 2 is described twice"), std::string::npos) << e.message;
  e = expect_error("{\"plants\": [], \"materials\": {\"1\": {}}}");
  EXPECT_NE(e.message.find("materials must be an array"), std::string::npos) << e.message;
}

TEST(SceneMaterials, AnImageOnTheSegmentsReadsItsRepeatsWritesThemBackAndNeedsAnImage) {
  test::TempFolder dir;
  test::write_rgb_png(dir.file("skin.png"), 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{}; });
  Expected<Scene> s = parse_scene_json(R"({"plants": [], "materials": [
      {"index": 2, "albedo": "skin.png", "v_per_metre": 6},
      {"index": 3, "albedo": "skin.png", "u_repeat": 4, "v_per_metre": 0.5},
      {"index": 4, "albedo": "skin.png"}]})",
                                       "m.scene.json", dir.path());
  ASSERT_TRUE(s.ok()) << s.error().format();
  EXPECT_EQ(s->materials.at(2).segment_repeat, (SceneMaterial::Repeat{1, 6}));  // u_repeat defaults to 1
  EXPECT_EQ(s->materials.at(3).segment_repeat, (SceneMaterial::Repeat{4, 0.5}));
  EXPECT_FALSE(s->materials.at(4).segment_repeat) << "no repeats: the segments take the image's mean";
  Expected<std::string> written = write_scene_json(*s, dir.path());
  ASSERT_TRUE(written.ok()) << written.error().message;
  Expected<Scene> again = parse_scene_json(*written, "m.scene.json", dir.path());
  ASSERT_TRUE(again.ok()) << again.error().format() << "\n" << *written;
  EXPECT_EQ(again->materials, s->materials);

  struct Bad {
    const char* entry;
    const char* says;
    uint32_t column;
  };
  const Bad bad[] = {
      {R"({"index": 1, "u_repeat": 2})", "materials[0].u_repeat lays an albedo image on the segments", 41},
      {R"({"index": 1, "albedo": [1, 1, 1], "v_per_metre": 2})", "materials[0].v_per_metre lays an albedo image", 65},
      {R"({"index": 1, "albedo": "skin.png", "u_repeat": 0})", "materials[0].u_repeat must be in (0, 1e+06]", 63},
      {R"({"index": 1, "albedo": "skin.png", "v_per_metre": "2"})", "materials[0].v_per_metre", 66},
  };
  for (const Bad& b : bad) {
    const std::string text = std::string("{\"plants\": [],\n \"materials\": [") + b.entry + "]}";
    Expected<Scene> r = parse_scene_json(text, "s.scene.json", dir.path());
    ASSERT_FALSE(r.ok()) << b.entry;
    EXPECT_EQ(r.error().loc.line, 2u) << b.entry;
    EXPECT_EQ(r.error().loc.column, b.column) << b.entry << ": " << r.error().message;
    EXPECT_NE(r.error().message.find(b.says), std::string::npos) << b.entry << ": " << r.error().message;
  }
}

TEST(SceneMaterials, SegmentTextureIsTheBarksOnWoodThenTheTablesWithRepeats) {
  std::map<uint32_t, SceneMaterial> table;
  table[0].albedo_image = "wood.png";
  table[0].segment_repeat = SceneMaterial::Repeat{2, 3};
  table[1].albedo_image = "leaf.png";  // no repeats: none on segments
  table[2].albedo_image = "skin.png";
  table[2].segment_repeat = SceneMaterial::Repeat{5, 7};
  Bark none, textured, coloured;
  textured.albedo_texture = "bark.png";
  textured.u_repeat = 8;
  coloured.albedo_rgb = glm::dvec3(0.5);
  auto path = [&](const Bark* bark, uint32_t m) {
    const std::optional<SegmentTexture> t = segment_texture(table, bark, m);
    return t ? t->path : std::string("-");
  };
  EXPECT_EQ(path(&textured, 0), "bark.png");
  EXPECT_EQ(segment_texture(table, &textured, 0)->u_repeat, 8);
  EXPECT_TRUE(segment_texture(table, &textured, 0)->from_bark);
  EXPECT_EQ(path(&coloured, 0), "-");
  EXPECT_EQ(path(&none, 0), "wood.png");
  EXPECT_EQ(segment_texture(table, &none, 0)->v_per_metre, 3);
  EXPECT_FALSE(segment_texture(table, &none, 0)->from_bark);
  EXPECT_EQ(path(nullptr, 0), "wood.png");
  EXPECT_EQ(path(&textured, 1), "-");
  EXPECT_EQ(path(&textured, 2), "skin.png");
  EXPECT_EQ(segment_texture(table, &coloured, 2)->u_repeat, 5);
  EXPECT_EQ(path(&none, 3), "-");
}

TEST(Scene, MalformedJsonIsLocated) {
  Diagnostic e = expect_error("{\"plants\": [],\n}");
  EXPECT_EQ(e.loc.line, 1u);  // the trailing comma
  EXPECT_EQ(e.loc.column, 14u);
}

TEST(Scene, DefaultSceneFramesTheSkeletonFromAThreeQuarterView) {
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.3, 0}, {{0, 6, 0}, 0.3, 0}};
  sk.chains = {{0, 2, std::nullopt}};
  Scene s = default_scene_for(sk, 320, 240);
  EXPECT_EQ(s.width, 320u);
  ASSERT_EQ(s.plants.size(), 1u);
  EXPECT_TRUE(s.plants[0].skeleton);
  EXPECT_FALSE(s.fog);
  EXPECT_NEAR(glm::dot(s.sun.direction, glm::normalize(glm::dvec3(0.5, 1, 0.3))), 1.0, 1e-15);
  EXPECT_EQ(s.ground.height, 0);
  EXPECT_NEAR(s.camera.target.y, 3, 1e-12);  // the box centre
  EXPECT_GT(s.camera.eye.x, 0);              // front right, above
  EXPECT_GT(s.camera.eye.z, s.camera.eye.x);
  EXPECT_GT(s.camera.eye.y, s.camera.target.y);
  // Every corner of the bounds (joints grown by radii) projects inside the image, and the
  // tightest one touches the 8% margin: the plant fills the frame.
  const glm::dvec3 lo(-0.3, -0.3, -0.3), hi(0.3, 6.3, 0.3);
  const glm::dvec3 fwd = glm::normalize(s.camera.target - s.camera.eye);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, s.camera.up)), up = glm::cross(right, fwd);
  const double ty = std::tan(0.5 * s.camera.fov_y_deg * 3.14159265358979 / 180), tx = ty * 320 / 240;
  double fill = 0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 c((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec3 q = c - s.camera.eye;
    const double z = glm::dot(q, fwd);
    ASSERT_GT(z, 0);
    fill = std::max({fill, std::abs(glm::dot(q, right)) / (z * tx), std::abs(glm::dot(q, up)) / (z * ty)});
  }
  EXPECT_LE(fill, 1 / 1.08 + 1e-9);
  EXPECT_GT(fill, 1 / 1.08 - 1e-9);
}

// ---- a plant's grammar error: the grammar's place, and a note at the scene's key -------

// ---- write_scene_json: what it writes reads back equal ---------------------------------

// `s` without the places it was read from (file, grammar_loc): not what the scene is.
Scene without_places(Scene s) {
  s.file.clear();
  for (ScenePlant& p : s.plants) p.grammar_loc = {};
  for (SceneScatter& sc : s.scatter) sc.grammar_loc = {};
  return s;
}

TEST(SceneWrite, WritesEveryKeyInScenemdOrderOneSectionPerLine) {
  Scene s;
  s.width = 320;
  s.height = 200;
  s.sun.direction = {0, 1, 0};
  s.fog = Fog{};
  ScenePlant p;
  p.grammar = "presets/saguaro.lsys";
  p.seed = 3;
  p.defines = {{"N", 5}};
  s.plants.push_back(p);
  Expected<std::string> text = write_scene_json(s);
  ASSERT_TRUE(text.ok()) << text.error().format();
  EXPECT_EQ(*text,
            "{\n"
            "  \"format\": \"sylva-scene\",\n"
            "  \"version\": 1,\n"
            "  \"camera\": {\"eye\": [6,3,6], \"target\": [0,2,0], \"up\": [0,1,0], \"fov_y_deg\": 40},\n"
            "  \"image\": {\"width\": 320, \"height\": 200},\n"
            "  \"sun\": {\"direction\": [0,1,0], \"angular_radius_deg\": 0.27, \"radiance\": [3,3,2.8]},\n"
            "  \"sky\": [0.25,0.3,0.4],\n"
            "  \"ground\": {\"height\": 0, \"albedo\": [0.35,0.3,0.25]},\n"
            "  \"fog\": {\"sigma_s\": 0.05, \"sigma_a\": 0.005, \"g\": 0.6, \"height_falloff\": 0, \"mode\": \"auto\", "
            "\"steps\": 64, \"photons\": 1000000},\n"
            "  \"plants\": [\n"
            "    {\"grammar\": \"presets/saguaro.lsys\", \"seed\": 3, \"defines\": {\"N\": 5}, \"position\": [0,0,0], "
            "\"rotate_y_deg\": 0, \"scale\": 1, \"bark\": {\"relief_depth\": 0.02, \"u_repeat\": 1, \"v_per_metre\": 1}}\n"
            "  ]\n"
            "}\n");
}

TEST(SceneWrite, ASceneWithEveryKeySetReadsBackEqual) {
  test::TempFolder dir;
  std::filesystem::create_directories(dir.file("textures"));
  test::write_rgb_png(dir.file("textures/bark.png"), 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{}; });
  test::write_rgb_png(dir.file("textures/h.png"), 2, 2, [](uint32_t, uint32_t) { return std::array<float, 3>{}; });
  Scene s;
  s.camera = {{1.5, 2.25, -7}, {0.1, 1, 0.3}, {0, 1, 0.01}, 33.3};
  s.width = 1920;
  s.height = 1080;
  s.sun = {unit_sun_direction({0.3, 0.9, -0.2}), 0.5, {10, 9.5, 8.25}};
  s.sky = {0.1, 0.2, 1e-3};
  s.ground = {-0.75, {0.5, 0.25, 0.125}};
  s.fog = Fog{0.125, 0.01, -0.3, 0.05, 12.5, FogMode::refined, 9, 4321};
  s.materials = {{0, {std::nullopt, 0.125}}, {1, {glm::dvec3(0.05, 0.25, 1e-3), 0.5}}, {15, {glm::dvec3(1, 0, 0.5), 1}}};
  s.animation = SceneAnimation{AnimationMotion::dance, 29.97, 2.5, {0.5, 0, -1}, 7.5, 0.25, 1.5, 3.75, 18446744073709551615u};
  ScenePlant textured;
  textured.grammar = dir.file("g.lsys");
  textured.seed = 18446744073709551615u;
  textured.steps = 7;
  textured.defines = {{"N", 4}, {"ANGLE", 22.5}, {"tiny", 1e-300}};
  textured.position = {1, -2, 3.5};
  textured.rotate_y_deg = -45;
  textured.scale = 0.3;
  textured.bark.albedo_texture = dir.file("textures/bark.png");
  textured.bark.height_texture = dir.file("textures/h.png");
  textured.bark.relief_depth_m = 0.015;
  textured.bark.u_repeat = 3;
  textured.bark.v_per_metre = 0.5;
  ScenePlant coloured;
  coloured.grammar = dir.file("other.lsys");
  coloured.bark.albedo_rgb = glm::dvec3(0.3, 0.2, 0.1);
  s.plants = {textured, coloured};
  const std::string folder = dir.file("scenes");
  std::filesystem::create_directories(folder);
  Expected<std::string> text = write_scene_json(s, folder);
  ASSERT_TRUE(text.ok()) << text.error().format();
  EXPECT_NE(text->find("\"albedo\": \"../textures/bark.png\""), std::string::npos) << *text;  // relative to the file
  EXPECT_NE(text->find("\"seed\": 18446744073709551615"), std::string::npos) << *text;
  Expected<Scene> back = parse_scene_json(*text, "every.scene.json", folder);
  ASSERT_TRUE(back.ok()) << back.error().format() << *text;
  EXPECT_EQ(without_places(*back), s);
  // Written into a file and read from there, too.
  const std::string path = folder + "/every.scene.json";
  std::ofstream(path) << *text;
  Expected<Scene> from_file = read_scene_file(path);
  ASSERT_TRUE(from_file.ok()) << from_file.error().format();
  EXPECT_EQ(without_places(*from_file), s);
  EXPECT_EQ(from_file->file, path);
}

TEST(SceneWrite, EveryBundledSceneReadsBackEqualAndWritesTheSameBytesAgain) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(SYLVA_SOURCE_DIR) + "/presets/scenes")) {
    const std::string path = entry.path().string();
    if (path.size() < 11 || path.substr(path.size() - 11) != ".scene.json") continue;
    ++scenes;
    const std::string folder = entry.path().parent_path().string();
    Expected<Scene> read = read_scene_file(path);
    ASSERT_TRUE(read.ok()) << read.error().format();
    Expected<std::string> text = write_scene_json(*read, folder);
    ASSERT_TRUE(text.ok()) << text.error().format();
    Expected<Scene> back = parse_scene_json(*text, path, folder);
    ASSERT_TRUE(back.ok()) << back.error().format();
    EXPECT_EQ(without_places(*back), without_places(*read)) << path;
    EXPECT_EQ(write_scene_json(*back, folder).value(), *text) << path;
  }
  EXPECT_GE(scenes, 2);
}

TEST(SceneWrite, SunDirectionsMadeAsTheReaderMakesThemReadBackExactly) {
  // Normalising twice need not give the same bits as once; the writer finds a vector the
  // reader normalises to exactly the stored one.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 500; ++trial) {
    glm::dvec3 d(u(rng), u(rng), u(rng));
    if (glm::length(d) < 1e-3) continue;
    Scene s;
    s.sun.direction = unit_sun_direction(d);
    ScenePlant p;
    p.grammar = "g.lsys";
    s.plants.push_back(p);
    Expected<Scene> back = parse_scene_json(write_scene_json(s).value(), "s.scene.json", "");
    ASSERT_TRUE(back.ok()) << back.error().format();
    ASSERT_EQ(back->sun.direction, s.sun.direction) << trial;
  }
}

TEST(SceneWrite, APlantWithoutAGrammarCannotBeWritten) {
  Skeleton sk;
  sk.joints = {{{0, 0, 0}, 0.1, 0}, {{0, 1, 0}, 0.1, 0}};
  sk.chains = {{0, 2, std::nullopt}};
  const Expected<std::string> text = write_scene_json(default_scene_for(sk));
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.error().message.find("plants[0] has no grammar"), std::string::npos) << text.error().format();
}

}  // namespace

// docs/limits.md: world coordinates within 1e12 m; directions of any finite size.
TEST(SceneLimits, CoordinatesBeyondTheLimitAreErrorsAtTheirNumber) {
  Diagnostic e = expect_error("{\"plants\": [], \"camera\": {\"eye\": [0, 1e200, 5]}}");
  EXPECT_EQ(e.message, "camera.eye coordinates must be within ±1e12 m (docs/limits.md), not 1e200");
  EXPECT_EQ(e.loc.column, 38u);
  e = expect_error("{\"plants\": [{\"grammar\": \"g.lsys\", \"position\": [-2e12, 0, 0]}]}");
  EXPECT_NE(e.message.find("plants[0].position coordinates must be within"), std::string::npos) << e.message;
}

TEST(SceneLimits, HugeAndTinyDirectionsAreNormalisedSafely) {
  Expected<Scene> r = parse_scene_json("{\"plants\": [], \"sun\": {\"direction\": [1e200, 1e200, 0]}}", "s.scene.json", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_NEAR(r->sun.direction.x, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(r->sun.direction.y, std::sqrt(0.5), 1e-15);
  EXPECT_EQ(r->sun.direction.z, 0);
  r = parse_scene_json("{\"plants\": [], \"sun\": {\"direction\": [0, 1e-300, 0]}}", "s.scene.json", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_EQ(r->sun.direction, glm::dvec3(0, 1, 0));
  // An up vector too long to square is still not parallel to the view direction.
  r = parse_scene_json("{\"plants\": [], \"camera\": {\"eye\": [0, 1, 5], \"up\": [0, 1e300, 0]}}",
                       "s.scene.json", "");
  ASSERT_TRUE(r.ok()) << r.error().format();
  EXPECT_TRUE(std::isfinite(glm::length(r->camera.up)));
  Diagnostic e = expect_error("{\"plants\": [], \"sun\": {\"direction\": [0, 0, 0]}}");
  EXPECT_NE(e.message.find("sun.direction must not be zero"), std::string::npos) << e.message;
}

TEST(SceneLimits, AnImageOverThePixelLimitIsRefusedBeforeAnythingIsAllocated) {
  Diagnostic e = expect_error("{\"plants\": [], \"image\": {\"width\": 65536, \"height\": 65536}}");
  EXPECT_EQ(e.message,
            "image: the image has 4294967296 pixels (65536x65536), more than the limit of 67108864 (8192x8192; "
            "docs/limits.md)");
}

}  // namespace sylva

namespace sylva {

// ---- The animation key (docs/animation.md) ------------------------------------------------

namespace {

Expected<Scene> scene_with_animation(const std::string& animation) {
  return parse_scene_json(R"({"animation": )" + animation + R"(, "plants": []})", "a.scene.json", "");
}

}  // namespace

TEST(SceneAnimationKey, AbsentMeansStillAndMotionSetsTheDefaultsTheKeysReplace) {
  auto still = parse_scene_json(R"({"plants": []})", "s.scene.json", "");
  ASSERT_TRUE(still) << still.error().format();
  EXPECT_FALSE(still->animation);

  auto sway = scene_with_animation("{}");
  ASSERT_TRUE(sway) << sway.error().format();
  ASSERT_TRUE(sway->animation);
  EXPECT_EQ(*sway->animation, SceneAnimation{});
  EXPECT_EQ(animation_frame_count(*sway->animation), 96u);  // 4 s at 24 fps

  auto dance = scene_with_animation(R"({"motion": "dance", "fps": 30, "duration_s": 0.5, "branch_amplitude_deg": 1})");
  ASSERT_TRUE(dance) << dance.error().format();
  SceneAnimation expected = animation_defaults(AnimationMotion::dance);
  expected.fps = 30;
  expected.duration_s = 0.5;
  expected.branch_amplitude_deg = 1;
  EXPECT_EQ(*dance->animation, expected);
  EXPECT_GT(expected.amplitude_deg, SceneAnimation{}.amplitude_deg);  // dance bends further than sway
  EXPECT_EQ(animation_frame_count(expected), 15u);
  // A duration that is not a whole number of frames rounds up; a tiny one is one frame.
  SceneAnimation odd;
  odd.duration_s = 0.1;
  odd.fps = 24;
  EXPECT_EQ(animation_frame_count(odd), 3u);
  odd.duration_s = 1e-9;
  EXPECT_EQ(animation_frame_count(odd), 1u);
}

TEST(SceneAnimationKey, EveryBadValueIsALocatedError) {
  struct Case {
    const char* animation;
    const char* message;
  };
  for (const Case& c : std::vector<Case>{
           {R"({"motion": "jig"})", "animation.motion must be \"sway\" or \"dance\", not \"jig\""},
           {R"({"motion": 3})", "animation.motion must be"},
           {R"({"fps": 0})", "animation.fps must be in (0, 1000]"},
           {R"({"fps": 1001})", "animation.fps must be in (0, 1000]"},
           {R"({"duration_s": -1})", "animation.duration_s must be in (0, 1e+06]"},
           {R"({"amplitude_deg": 90.5})", "animation.amplitude_deg must be in [0, 90]"},
           {R"({"frequency_hz": -0.1})", "animation.frequency_hz must be in [0, 100]"},
           {R"({"branch_amplitude_deg": "big"})", "animation.branch_amplitude_deg must be a number"},
           {R"({"wind": [1, 0]})", "animation.wind must be an array of 3 numbers"},
           {R"({"wind": [1e7, 0, 0]})", "animation.wind components must be within"},
           {R"({"seed": -1})", "animation.seed must be an integer"},
           {R"({"fps": 1000, "duration_s": 1000})", "more than 100000 frames"},
           {R"({"speed": 2})", "unknown key \"speed\" in animation"},
           {R"([1])", "animation must be an object"},
       }) {
    auto r = scene_with_animation(c.animation);
    ASSERT_FALSE(r) << c.animation;
    EXPECT_NE(r.error().message.find(c.message), std::string::npos) << c.animation << " -> " << r.error().format();
    EXPECT_EQ(r.error().loc.line, 1u) << c.animation;
    EXPECT_GT(r.error().loc.column, 14u) << c.animation;  // at the value, inside the animation object
  }
}

}  // namespace sylva

// ---- Scatter entries (docs/scatter.md) ------------------------------------------------------

namespace sylva {
namespace {

const std::string kCactusGrammar = std::string(SYLVA_SOURCE_DIR) + "/presets/cactus.lsys";

Expected<Scene> scene_with_scatter(const std::string& entry) {
  return parse_scene_json(R"({"ground": {"height": -0.5}, "plants": [], "scatter": [)" + entry + "]}", "s.scene.json",
                          "");
}

std::string cactus_entry(const std::string& rest) {
  return R"({"grammar": ")" + kCactusGrammar + R"(", )" + rest + "}";
}

}  // namespace

TEST(SceneScatterKey, PlacesCountPlantsInsideTheDiscApartAndWithinTheirRanges) {
  auto s = scene_with_scatter(cactus_entry(
      R"("count": 300, "disc": {"centre": [10, -4], "radius": 15}, "seed": 9, "plant_seeds": [3, 7],
         "rotate_y_deg": [-30, 30], "scale": [0.5, 2], "min_spacing": 1.1)"));
  ASSERT_TRUE(s) << s.error().format();
  ASSERT_EQ(s->plants.size(), 300u);
  ASSERT_EQ(s->scatter.size(), 1u);
  std::set<uint64_t> seeds;
  for (size_t i = 0; i < s->plants.size(); ++i) {
    const ScenePlant& p = s->plants[i];
    EXPECT_EQ(p.scatter, 1u);
    EXPECT_EQ(p.grammar, kCactusGrammar);
    EXPECT_EQ(p.position.y, -0.5);  // on the ground
    EXPECT_LE(std::hypot(p.position.x - 10, p.position.z + 4), 15.0);
    EXPECT_GE(p.rotate_y_deg, -30);
    EXPECT_LE(p.rotate_y_deg, 30);
    EXPECT_GE(p.scale, 0.5);
    EXPECT_LE(p.scale, 2);
    ASSERT_TRUE(p.seed);
    seeds.insert(*p.seed);
    for (size_t j = 0; j < i; ++j)  // every pair, against the grid's shortcut
      EXPECT_GE(std::hypot(p.position.x - s->plants[j].position.x, p.position.z - s->plants[j].position.z), 1.1)
          << i << ", " << j;
  }
  EXPECT_EQ(seeds, (std::set<uint64_t>{3, 4, 5, 6, 7}));
  // Deterministic: the same entry places the same plants.
  auto again = scene_with_scatter(cactus_entry(
      R"("count": 300, "disc": {"centre": [10, -4], "radius": 15}, "seed": 9, "plant_seeds": [3, 7],
         "rotate_y_deg": [-30, 30], "scale": [0.5, 2], "min_spacing": 1.1)"));
  ASSERT_TRUE(again);
  EXPECT_EQ(again->plants, s->plants);
  // Another seed, other places.
  auto other = scene_with_scatter(cactus_entry(R"("count": 400, "disc": {"centre": [10, -4], "radius": 15}, "seed": 10)"));
  ASSERT_TRUE(other);
  EXPECT_NE(other->plants.front().position, s->plants.front().position);
}

TEST(SceneScatterKey, APolygonKeepsItsPlantsInsideEvenWhereItIsConcaveAndDensitySetsTheCount) {
  // An L: the square [0, 10]² without its quadrant [5, 10]²: 75 m².
  auto s = scene_with_scatter(
      cactus_entry(R"("density": 2, "polygon": [[0, 0], [10, 0], [10, 5], [5, 5], [5, 10], [0, 10]], "seed": 1)"));
  ASSERT_TRUE(s) << s.error().format();
  EXPECT_EQ(s->plants.size(), 150u);
  size_t in_each_arm[2] = {0, 0};
  for (const ScenePlant& p : s->plants) {
    EXPECT_TRUE(p.position.x >= 0 && p.position.x <= 10 && p.position.z >= 0 && p.position.z <= 10);
    EXPECT_FALSE(p.position.x > 5 && p.position.z > 5) << p.position.x << ", " << p.position.z;
    in_each_arm[p.position.x > 5 ? 0 : p.position.z > 5 ? 1 : 0] += p.position.x > 5 || p.position.z > 5;
  }
  EXPECT_GT(in_each_arm[0], 20u);  // both arms are used
  EXPECT_GT(in_each_arm[1], 20u);
}

TEST(SceneScatterKey, EntriesThatCannotFitOrSayTooLittleOrTooMuchAreLocatedErrors) {
  struct Case {
    std::string entry;
    const char* message;
  };
  const std::string disc = R"("disc": {"radius": 2})";
  for (const Case& c : std::vector<Case>{
           {cactus_entry(R"("count": 200, "min_spacing": 1, )" + disc), "plants fit 1 m apart in the area of"},
           {cactus_entry(R"("count": 5)"), "needs exactly one area"},
           {cactus_entry(R"("count": 5, "polygon": [[0, 0], [1, 1], [2, 2]])"), "encloses no area"},
           {cactus_entry(R"("count": 5, "polygon": [[0, 0], [1, 1]])"), "at least 3 corners"},
           {cactus_entry(R"("count": 5, "density": 1, )" + disc), "exactly one of \"count\" and \"density\""},
           {cactus_entry(R"("count": 0, )" + disc), "count must be an integer from 1 to 1000000"},
           {cactus_entry(R"("count": 1000001, )" + disc), "count must be an integer from 1 to 1000000"},
           {cactus_entry(R"("density": 1e6, )" + disc), "must give 1 to 1000000 plants"},
           {cactus_entry(R"("count": 5, "plant_seeds": [9, 2], )" + disc), "first <= last"},
           {cactus_entry(R"("count": 5, "scale": [2, 1], )" + disc), "low <= high"},
           {cactus_entry(R"("count": 5, "scale": 0, )" + disc), "scale must be in (0, 1e+09]"},
           {cactus_entry(R"("count": 5, "disc": {"radius": -1})"), "disc.radius must be in (0, 1e+09]"},
           {cactus_entry(R"("count": 5, "spread": 1, )" + disc), "unknown key \"spread\" in scatter[0]"},
           {R"({"count": 5, "disc": {"radius": 2}})", "scatter[0] needs a \"grammar\""},
       }) {
    auto r = scene_with_scatter(c.entry);
    ASSERT_FALSE(r) << c.entry;
    EXPECT_NE(r.error().message.find(c.message), std::string::npos) << c.entry << " -> " << r.error().format();
    EXPECT_EQ(r.error().loc.line, 1u) << c.entry;
  }
}

// Issue 32, item 11: a polygon of 80,000 corners made every dart test every edge. The
// banded test gives inside_polygon's answer exactly, for points anywhere (at corners'
// heights too), while a point tests a handful of edges.
TEST(SceneScatterKey, TheBandedPointInPolygonTestAgreesWithTheFullWalkAndTestsFewEdges) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0, 1);
  auto star = [&](size_t n, double jag) {  // radii from 100 − jag to 100
    std::vector<glm::dvec2> p;
    for (size_t i = 0; i < n; ++i) {
      const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n), r = 100 - jag * unit(rng);
      p.push_back({r * std::cos(a), std::round(r * std::sin(a))});  // many corners share a height
    }
    return p;
  };
  std::vector<glm::dvec2> comb;  // 40 full-height teeth
  comb.push_back({0, 0});
  comb.push_back({80, 0});
  for (int k = 39; k >= 0; --k)
    for (glm::dvec2 q : {glm::dvec2(2 * k + 1.5, 1), glm::dvec2(2 * k + 1.5, 100), glm::dvec2(2 * k + 0.5, 100),
                         glm::dvec2(2 * k + 0.5, 1)})
      comb.push_back(q);
  for (const std::vector<glm::dvec2>& polygon : {star(7, 50), star(300, 50), star(5000, 50), star(5000, 1), comb}) {
    const PolygonBands bands(polygon);
    glm::dvec2 lo = polygon[0], hi = polygon[0];
    for (const glm::dvec2& q : polygon) lo = glm::min(lo, q), hi = glm::max(hi, q);
    for (int k = 0; k < 20000; ++k) {
      glm::dvec2 p(lo.x - 1 + unit(rng) * (hi.x - lo.x + 2), lo.y - 1 + unit(rng) * (hi.y - lo.y + 2));
      if (k % 4 == 0) p.y = polygon[static_cast<size_t>(k) % polygon.size()].y;  // exactly a corner's height
      ASSERT_EQ(bands.inside(p), inside_polygon(polygon, p)) << polygon.size() << " corners at " << p.x << ", " << p.y;
    }
  }
  // A wiggly outline (a forest stand's): a horizontal line meets a few of its edges.
  EXPECT_LT(PolygonBands(star(80000, 0.005)).mean_band_edges(), 12);
  EXPECT_LT(PolygonBands(comb).mean_band_edges(), 9.5 * static_cast<double>(comb.size()));  // memory bound
}

TEST(SceneScatterKey, APolygonOfEightyThousandCornersPlacesItsPlantsAndAHopelessCombIsRefused) {
  std::string corners;
  for (int i = 0; i < 80000; ++i) {
    const double a = 2 * M_PI * i / 80000.0, r = 20 + (i % 2);  // a fine star
    corners += (i ? ", [" : "[") + std::to_string(r * std::cos(a)) + ", " + std::to_string(r * std::sin(a)) + "]";
  }
  auto placed = scene_with_scatter(cactus_entry(R"("count": 2000, "polygon": [)" + corners + "]"));
  ASSERT_TRUE(placed) << placed.error().format();
  EXPECT_EQ(placed->plants.size(), 2000u);
  // 40,000 full-height teeth and a million plants: ~10^15 edge tests, refused at the entry.
  std::string teeth = "[0, 0], [80000, 0]";
  for (int k = 39999; k >= 0; --k)
    teeth += ", [" + std::to_string(2 * k + 1.5) + ", 1], [" + std::to_string(2 * k + 1.5) + ", 100], [" +
             std::to_string(2 * k + 0.5) + ", 100], [" + std::to_string(2 * k + 0.5) + ", 1]";
  auto refused = scene_with_scatter(cactus_entry(R"("count": 1000000, "polygon": [)" + teeth + "]"));
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("simplify the polygon or lower the count"), std::string::npos)
      << refused.error().format();
  EXPECT_EQ(refused.error().loc.line, 1u);
}

// Issue 31 §2: a disc's `fade` thins the plants linearly to nothing at its rim. Against the
// closed form: with radius R faded over f, the share of plants in the band R − f < r ≤ R is
// (R·f − 2f²/3) / (R² − R·f + f²/3), the outer half of the band holds ∫ r(R − r) over it
// against the whole band's (at R = 20, f = 8: 0.449 and 0.296 of that), and
// none stands in the last few centimetres; the darts inside stay where they were.
TEST(SceneScatterKey, ADiscsFadeThinsItsRimAsTheClosedFormSaysAndLeavesTheInsideAlone) {
  const double R = 20, f = 8;
  const size_t n = 20000;
  auto faded = scene_with_scatter(cactus_entry(
      R"("count": 20000, "disc": {"centre": [3, -2], "radius": 20, "fade": 8}, "seed": 5)"));
  ASSERT_TRUE(faded) << faded.error().format();
  ASSERT_EQ(faded->plants.size(), n);
  size_t band = 0, outer_half = 0, last_cm = 0;
  for (const ScenePlant& p : faded->plants) {
    const double r = std::hypot(p.position.x - 3, p.position.z + 2);
    ASSERT_LE(r, R);
    band += r > R - f;
    outer_half += r > R - f / 2;
    last_cm += r > R - 0.02;
  }
  const double share = (R * f - 2 * f * f / 3) / (R * R - R * f + f * f / 3);
  const double sigma = std::sqrt(share * (1 - share) / static_cast<double>(n));
  EXPECT_NEAR(static_cast<double>(band) / n, share, 4 * sigma) << band;
  // ∫_{R−f/2}^{R} r(R − r) dr / ∫_{R−f}^{R} r(R − r) dr
  auto integral = [&](double a) { return R * (R * R - a * a) / 2 - (R * R * R - a * a * a) / 3; };
  const double outer_share = integral(R - f / 2) / integral(R - f);
  EXPECT_NEAR(static_cast<double>(outer_half) / static_cast<double>(band), outer_share,
              4 * std::sqrt(outer_share * (1 - outer_share) / static_cast<double>(band)));
  EXPECT_LT(last_cm, 3u);  // about 0.08 expected
  // A hard-edged disc of the same seed puts more than twice as many there (0.36 of 20,000).
  auto hard = scene_with_scatter(cactus_entry(R"("count": 20000, "disc": {"centre": [3, -2], "radius": 20}, "seed": 5)"));
  ASSERT_TRUE(hard);
  size_t hard_outer = 0;
  for (const ScenePlant& p : hard->plants) hard_outer += std::hypot(p.position.x - 3, p.position.z + 2) > R - f / 2;
  EXPECT_GT(hard_outer, 2 * outer_half);
  // `fade: 0` is the hard edge, plant for plant.
  auto zero = scene_with_scatter(
      cactus_entry(R"("count": 20000, "disc": {"centre": [3, -2], "radius": 20, "fade": 0}, "seed": 5)"));
  ASSERT_TRUE(zero);
  EXPECT_EQ(zero->plants, hard->plants);
  // The darts that land inside the fade are the hard disc's: its first plants inside
  // R − f are the faded disc's first plants inside R − f, in order.
  std::vector<glm::dvec3> inner_hard, inner_faded;
  for (const ScenePlant& p : hard->plants)
    if (std::hypot(p.position.x - 3, p.position.z + 2) <= R - f) inner_hard.push_back(p.position);
  for (const ScenePlant& p : faded->plants)
    if (std::hypot(p.position.x - 3, p.position.z + 2) <= R - f) inner_faded.push_back(p.position);
  ASSERT_GT(inner_faded.size(), 1000u);
  for (size_t i = 0; i < std::min(inner_hard.size(), inner_faded.size()); ++i)
    ASSERT_EQ(inner_hard[i], inner_faded[i]) << i;
}

TEST(SceneScatterKey, DensityOverAFadedDiscCountsTheRimByItsWeightAndAFadePastTheRadiusIsAnError) {
  // R = 10, f = 6: π(100 − 60 + 12) = 52π m², 2 plants per m² -> 327 plants (not 628).
  auto s = scene_with_scatter(cactus_entry(R"("density": 2, "disc": {"radius": 10, "fade": 6})"));
  ASSERT_TRUE(s) << s.error().format();
  EXPECT_EQ(s->plants.size(), static_cast<size_t>(std::round(2 * 52 * M_PI)));
  EXPECT_NEAR(scatter_weighted_area_m2(s->scatter[0]), 52 * M_PI, 1e-9);
  EXPECT_EQ(scatter_rim_weight(s->scatter[0], {0, 0}), 1);
  EXPECT_EQ(scatter_rim_weight(s->scatter[0], {7, 0}), 0.5);
  EXPECT_EQ(scatter_rim_weight(s->scatter[0], {0, -10}), 0);
  for (const char* bad : {R"("count": 5, "disc": {"radius": 2, "fade": 3})", R"("count": 5, "disc": {"radius": 2, "fade": -1})",
                          R"("count": 5, "disc": {"radius": 2, "fade": "soft"})"}) {
    auto r = scene_with_scatter(cactus_entry(bad));
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message.find("disc.fade must be"), std::string::npos) << r.error().format();
    EXPECT_GT(r.error().loc.column, 60u) << r.error().format();  // at the value
  }
}

TEST(SceneScatterKey, WritesBackAsItsEntryAndReadsBackEqual) {
  auto s = parse_scene_json(R"({"plants": [{"grammar": ")" + kCactusGrammar + R"(", "seed": 2}], "scatter": [)" +
                                cactus_entry(R"("count": 30, "disc": {"centre": [1, 2], "radius": 6, "fade": 1.5}, "seed": 4,
                                   "plant_seeds": 8, "rotate_y_deg": 45, "scale": [1, 1.5], "min_spacing": 0.5,
                                   "steps": 3, "defines": {"HEIGHT": 1.1})") +
                                "," + cactus_entry(R"("density": 0.5, "polygon": [[0, 0], [4, 0], [0, 4]])") + "]}",
                            "w.scene.json", "");
  ASSERT_TRUE(s) << s.error().format();
  ASSERT_EQ(s->plants.size(), 1u + 30u + 4u);
  Expected<std::string> text = write_scene_json(*s);
  ASSERT_TRUE(text) << text.error().format();
  EXPECT_EQ(text->find("\"seed\": 2"), text->rfind("\"seed\": 2"));  // the scene's own plant, written once
  auto back = parse_scene_json(*text, "w.scene.json", "");
  ASSERT_TRUE(back) << back.error().format() << *text;
  back->file = s->file;
  for (size_t i = 0; i < back->plants.size(); ++i) back->plants[i].grammar_loc = s->plants[i].grammar_loc;
  for (size_t k = 0; k < back->scatter.size(); ++k) back->scatter[k].grammar_loc = s->scatter[k].grammar_loc;
  EXPECT_EQ(back->scatter, s->scatter);
  EXPECT_EQ(back->plants, s->plants);
}

}  // namespace sylva

namespace sylva {
namespace {

// docs/spec/scene.md "Skin": the scene's key is every plant's that names none; a plant's
// and a scatter entry's own win; --skin (override_skin) wins over all; writes back.
TEST(SceneSkinKey, APlantsOwnSkinWinsOverTheScenesAndTheFlagOverBoth) {
  const std::string g = kCactusGrammar;
  auto s = parse_scene_json(R"({"skin": "paper", "plants": [{"grammar": ")" + g + R"("},
    {"grammar": ")" + g + R"(", "skin": "smooth"}], "scatter": [)" +
                                cactus_entry(R"("count": 2, "disc": {"centre": [0, 0], "radius": 5})") + "," +
                                cactus_entry(R"("count": 2, "disc": {"centre": [9, 0], "radius": 5}, "skin": "smooth")") +
                                "]}",
                            "k.scene.json", "");
  ASSERT_TRUE(s) << s.error().format();
  EXPECT_EQ(s->skin, SkinStyle::paper);
  ASSERT_EQ(s->plants.size(), 6u);
  const std::vector<SkinStyle> expected = {SkinStyle::paper, SkinStyle::smooth, SkinStyle::paper,
                                           SkinStyle::paper, SkinStyle::smooth, SkinStyle::smooth};
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(s->plants[i].skin, expected[i]) << "plant " << i;
  // Written back: the scene's key, the plant that differs, the entry that names one.
  Expected<std::string> text = write_scene_json(*s);
  ASSERT_TRUE(text) << text.error().format();
  EXPECT_NE(text->find("\"skin\": \"paper\""), std::string::npos) << *text;
  auto back = parse_scene_json(*text, "k.scene.json", "");
  ASSERT_TRUE(back) << back.error().format() << *text;
  for (size_t i = 0; i < back->plants.size(); ++i) EXPECT_EQ(back->plants[i].skin, s->plants[i].skin) << i;
  EXPECT_EQ(back->scatter[1].skin, SkinStyle::smooth);
  EXPECT_FALSE(back->scatter[0].skin);
  // --skin smooth: every plant, whatever its key.
  Scene flagged = *s;
  override_skin(flagged, SkinStyle::smooth);
  for (const ScenePlant& p : flagged.plants) EXPECT_EQ(p.skin, SkinStyle::smooth);
  // Without any key nothing is written (scenes from before the key keep their bytes).
  auto plain = parse_scene_json(R"({"plants": [{"grammar": ")" + g + R"("}]})", "p.scene.json", "");
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->plants[0].skin, SkinStyle::smooth);
  EXPECT_EQ(write_scene_json(*plain)->find("skin"), std::string::npos);
}

TEST(SceneSkinKey, AnythingButSmoothOrPaperIsAnErrorAtTheKey) {
  Diagnostic e = expect_error("{\"plants\": [],\n \"skin\": \"mitred\"}");
  EXPECT_EQ(e.loc.line, 2u);
  EXPECT_EQ(e.loc.column, 10u);
  EXPECT_NE(e.message.find("skin must be \"smooth\" or \"paper\""), std::string::npos) << e.message;
  e = expect_error("{\"plants\": [{\"grammar\": \"g.lsys\", \"skin\": 1}]}");
  EXPECT_NE(e.message.find("plants[0].skin must be"), std::string::npos) << e.message;
  e = expect_error("{\"plants\": [], \"scatter\": [{\"grammar\": \"g.lsys\", \"count\": 1, \"skin\": \"Paper\"}]}");
  EXPECT_NE(e.message.find("scatter[0].skin must be"), std::string::npos) << e.message;
}

TEST(CameraFrame, FramePixelInvertsFrameRayAndRefusesPointsBehindTheEye) {
  // Random cameras and pixels: the point at distance t along a pixel's ray projects back to
  // that pixel at depth t·(forward · direction); a point behind the eye has no pixel.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    Scene s;
    s.camera.eye = {5 * u(rng), 5 * u(rng), 5 * u(rng)};
    s.camera.target = s.camera.eye + glm::dvec3(u(rng), u(rng), u(rng) + 2.5);
    s.camera.fov_y_deg = 20 + 70 * (u(rng) + 1);
    s.width = 320;
    s.height = 200;
    const render_common::CameraFrame f = render_common::camera_frame(s);
    const double x = 160 + 160 * u(rng), y = 100 + 100 * u(rng), t = 0.1 + 50 * (u(rng) + 1);
    const Ray r = render_common::frame_ray(f, x, y);
    const auto p = render_common::frame_pixel(f, r.origin + t * r.direction);
    ASSERT_TRUE(p);
    EXPECT_NEAR(p->x, x, 1e-6);
    EXPECT_NEAR(p->y, y, 1e-6);
    EXPECT_NEAR(p->depth, t * glm::dot(r.direction, f.forward), 1e-6 * t);
    EXPECT_FALSE(render_common::frame_pixel(f, r.origin - t * r.direction));
    EXPECT_FALSE(render_common::frame_pixel(f, f.eye));
  }
}

}  // namespace
}  // namespace sylva
