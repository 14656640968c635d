// plants.cpp — see plants.h.
#include "tests/support/plants.h"

#include <stdexcept>
#include <utility>

#include "core/grow/grow.h"
#include "core/scene/scene_json.h"

namespace sylva::test {

Skeleton grown(const char* text) {
  Expected<lsys::Grammar> grammar = lsys::parse_grammar(text, "test.lsys", {});
  if (!grammar.ok()) return {};
  Expected<GrowResult> result = grow(*grammar, {}, "test.lsys", {});
  return result.ok() ? std::move(result->skeleton) : Skeleton{};
}

Skeleton grown_as(const std::string& text, uint64_t seed, const std::string& grammar_path,
                  const std::map<std::string, double>& defines) {
  Expected<lsys::Grammar> grammar = lsys::parse_grammar(text, "plant.lsys", {});
  if (!grammar) throw std::runtime_error(grammar.error().format());
  lsys::DeriveOptions options;
  options.seed = seed;
  Expected<GrowResult> result = grow(*grammar, options, grammar_path, defines);
  if (!result) throw std::runtime_error(result.error().format());
  return std::move(result->skeleton);
}

Skeleton grow_preset(const std::string& name) {
  Scene scene;
  ScenePlant plant;
  plant.grammar = std::string(SYLVA_SOURCE_DIR) + "/presets/" + name + ".lsys";
  scene.plants.push_back(plant);
  if (Status grown = grow_scene_plants(scene); !grown) throw std::runtime_error(grown.error().format());
  return *scene.plants.front().skeleton;
}

Expected<Scene> read_and_grow_scene(const std::string& path) {
  Expected<Scene> read = read_scene_file(path);
  if (!read) return read;
  if (Status grown = grow_scene_plants(*read); !grown) return grown.error();
  return read;
}

Scene grown_preset_scene(const std::string& name) {
  Expected<Scene> scene = read_and_grow_scene(std::string(SYLVA_SOURCE_DIR) + "/presets/scenes/" + name + ".scene.json");
  if (!scene) throw std::runtime_error(scene.error().format());
  return std::move(*scene);
}

}  // namespace sylva::test
