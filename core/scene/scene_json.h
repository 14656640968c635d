// scene_json.h — docs/spec/scene.md's `.scene.json` read into a Scene (scene.h) and written back.
//
// The reader checks every key: a key it does not know, a value of the wrong type or out of
// its range is a Diagnostic at that key's line and column (code points), so a typo never
// silently changes a picture. Relative paths (grammars, textures) are resolved against the
// scene file's folder. A `scatter` entry's plants are placed here (scatter.h) and appended
// to Scene::plants; plants are not grown (core/grow/grow.h grow_scene_plants).
#pragma once

#include <string>
#include <string_view>

#include "core/scene/scene.h"
#include "core/util/diagnostic.h"

namespace sylva {

// Parses scene JSON. `file` names it in messages; relative paths in it (grammar,
// textures) are resolved against `base_dir` (the scene file's folder; "" = as written).
// Errors: the first problem, a Diagnostic at the offending key or value (no source line).
Expected<Scene> parse_scene_json(std::string_view text, std::string_view file, const std::string& base_dir);

// Reads and parses a scene file; paths in it are relative to its folder.
Expected<Scene> read_scene_file(const std::string& path);

// A scene's `animation` object alone (docs/animation.md), e.g. from Python's export_gltf;
// errors located in `text` as the scene reader locates them.
Expected<SceneAnimation> parse_animation_json(std::string_view text, std::string_view file);

// The scene as `.scene.json` text (docs/spec/scene.md) that parse_scene_json(text, file, base_dir)
// reads back equal to `scene` (but for the places: file, grammar_loc) when its sun
// direction is one the reader makes (unit_sun_direction; every scene read from a file
// has one): every key with its
// value, defaults included, optional keys (fog, seed, steps, bark textures) when set;
// numbers as shortest round-trip decimals; paths relative to `base_dir` (the folder the
// file will be in; "" = as stored) where they can be, else absolute. Deterministic:
// identical scenes give identical bytes. Error: a plant without a grammar (a scene made
// around a skeleton, default_scene_for, has nothing a scene file can name).
Expected<std::string> write_scene_json(const Scene& scene, const std::string& base_dir = "");

}  // namespace sylva
