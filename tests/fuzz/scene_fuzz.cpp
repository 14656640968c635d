// scene_fuzz.cpp — libFuzzer target: any bytes as a `.scene.json` scene (docs/spec/scene.md), its
// relative paths resolved against presets/scenes/ so that the presets' textures and
// grammars are found (a texture named by the input is opened from its header, as
// `sylva render` does). Properties beyond "no crash, no sanitizer finding": an error
// names the file; an accepted scene writes (write_scene_json) and reads back equal but
// for the places (file, the plants' and scatter entries' grammar_loc), as scene.h promises.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/scene/scene.h"
#include "core/scene/scene_json.h"
#include "tests/fuzz/fuzz_check.h"

namespace {

const std::string kBaseDir = SYLVA_SOURCE_DIR "/presets/scenes";

[[noreturn]] void fail(const char* what, const std::string& detail) { sylva::fuzz::fail("scene_fuzz", what, detail); }

void forget_places(sylva::Scene& scene) {
  scene.file.clear();
  for (sylva::ScenePlant& p : scene.plants) p.grammar_loc = {};
  for (sylva::SceneScatter& s : scene.scatter) s.grammar_loc = {};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  sylva::Expected<sylva::Scene> scene = sylva::parse_scene_json(text, "fuzz.scene.json", kBaseDir);
  if (!scene) {
    sylva::fuzz::check_error("scene_fuzz", scene.error(), "fuzz.scene.json");
    return 0;
  }
  sylva::Expected<std::string> json = sylva::write_scene_json(*scene, kBaseDir);
  if (!json) return 0;  // a plant without a grammar has nothing a scene file can name
  sylva::Expected<sylva::Scene> back = sylva::parse_scene_json(*json, "fuzz.scene.json", kBaseDir);
  if (!back) fail("a written scene does not read back", back.error().format() + "\n" + *json);
  forget_places(*scene);
  forget_places(*back);
  if (!(*back == *scene)) fail("a written scene reads back different", *json);
  return 0;
}
