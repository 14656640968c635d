// plants.h — test fixtures grown from grammars: the tests of the rooms below core/grow/
// (scene, io, the renderers) take plants as skeletons, and these make them with the real
// grower (sylva_test_plants links core/grow/) so that a test file itself includes only
// what its room may use (tests/layering).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/geometry/skeleton.h"
#include "core/scene/scene.h"

namespace sylva::test {

// The skeleton a grammar text grows into (named "test.lsys"; default seed and steps);
// empty when it fails.
Skeleton grown(const char* text);

// The skeleton `text` grows into with `seed`, its source recording `grammar_path` and
// `defines` (recorded only: the text's own #define lines apply). Throws
// std::runtime_error with the Diagnostic when it fails.
Skeleton grown_as(const std::string& text, uint64_t seed, const std::string& grammar_path,
                  const std::map<std::string, double>& defines);

// The skeleton presets/NAME.lsys grows with its own seed and steps (throws
// std::runtime_error with the Diagnostic when it fails).
Skeleton grow_preset(const std::string& name);

// The scene presets/scenes/NAME.scene.json, read and its plants grown (throws
// std::runtime_error with the Diagnostic when either fails).
Scene grown_preset_scene(const std::string& name);

// The scene at `path` with its plants grown (grow_scene_plants); the Diagnostic of the
// read or of the growth when either fails.
Expected<Scene> read_and_grow_scene(const std::string& path);

}  // namespace sylva::test
