// render_input.cpp — see render_input.h.
#include "app/front/render_input.h"

#include <chrono>
#include <filesystem>
#include <glm/common.hpp>
#include <iostream>
#include <limits>

#include "core/io/gltf.h"
#include "core/scene/render_common.h"
#include "core/grow/turtle.h"
#include "core/scene/scene_json.h"
#include "core/util/json.h"
#include "core/grow/grow.h"
#include "core/util/clock.h"
#include "app/front/light.h"

namespace sylva::cli {

bool is_grammar_input(const std::string& path) { return lsys::is_grammar_path(path); }

bool is_render_input(const std::string& path) {
  return path.ends_with(".scene.json") || path.ends_with(".skel.json") || is_grammar_input(path) ||
         path.ends_with(".glb") || path.ends_with(".gltf");
}

std::variant<Scene, ExitCode> load_render_input(const GrammarArgs& grammar, std::optional<uint32_t> width,
                                                std::optional<uint32_t> height,
                                                std::vector<RenderPass>& passes, const Progress& progress,
                                                std::optional<int64_t> growth_step) {
  const std::string& input = grammar.grammar;
  const bool is_scene = input.ends_with(".scene.json"), is_skeleton = input.ends_with(".skel.json"),
             is_gltf = input.ends_with(".glb") || input.ends_with(".gltf");
  auto start = std::chrono::steady_clock::now();
  Scene scene;
  if (is_scene) {
    Expected<Scene> read = read_scene_file(input);
    if (!read) {
      std::cerr << read.error().format();
      return kInputError;
    }
    scene = std::move(*read);
    passes.push_back({"read scene", seconds_since(start), ""});
    start = std::chrono::steady_clock::now();
    // A plant's grammar error: the grammar's place, and a note at the scene key naming it.
    if (Status grown = grow_scene_plants(scene, grammar.max_modules, progress, &cpu_light_oracle(), growth_step);
        !grown) {
      if (grown.cancelled()) return kInterrupted;
      std::cerr << grown.error().format();
      return kInputError;
    }
    passes.push_back({"grow", seconds_since(start), std::to_string(scene.plants.size()) + " plants"});
  } else if (is_gltf) {
    // A file written by `sylva export`: its skeletons come back exactly from node extras.
    Expected<std::vector<GltfPlant>> imported = import_gltf_skeletons(input);
    if (!imported) {
      std::cerr << imported.error().format();
      return kInputError;
    }
    for (const GltfPlant& p : *imported)
      if (auto problem = plant_extent_problem(p.skeleton, {p.position_m[0], p.position_m[1], p.position_m[2]},
                                              p.scale)) {
        std::cerr << file_diagnostic(input, "plant " + json_excerpt(p.name) + ": " + *problem).format();
        return kInputError;
      }
    const uint32_t w = width.value_or(1024), h = height.value_or(768);
    scene = default_scene_for(imported->front().skeleton, w, h);
    scene.plants.clear();
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    double lowest = 0;
    for (GltfPlant& p : *imported) {
      ScenePlant plant;
      plant.skeleton = std::move(p.skeleton);
      plant.position = {p.position_m[0], p.position_m[1], p.position_m[2]};
      plant.rotate_y_deg = p.rotate_y_deg;
      plant.scale = p.scale;
      plant.skin = p.skin;
      const Skeleton placed = place_plant(plant);
      const SkeletonBounds b = skeleton_bounds(placed);
      lo = glm::min(lo, b.lo);
      hi = glm::max(hi, b.hi);
      for (const Joint& j : placed.joints) lowest = std::min(lowest, j.position_m[1]);
      scene.plants.push_back(std::move(plant));
    }
    scene.ground.height = lowest;
    scene.camera = framing_camera(lo, hi, w, h);
    passes.push_back({"read glTF", seconds_since(start), std::to_string(scene.plants.size()) + " plants"});
  } else {
    Skeleton skeleton;
    if (is_skeleton) {
      Expected<Skeleton> read = read_skeleton_file(input);
      if (!read) {
        std::cerr << read.error().format();
        return kInputError;
      }
      skeleton = std::move(*read);
      passes.push_back({"read skeleton", seconds_since(start), ""});
    } else {
      lsys::ParseOptions po;
      po.define_overrides = grammar.defines;
      auto g = lsys::load_grammar(input, po);
      if (!g) {
        const sylva::Diagnostic& d = g.error();
        if (d.loc.line == 0 && d.message.rfind("-D ", 0) == 0) {
          std::cerr << "sylva render: error: " << d.message << "\n";
          return kUsageError;
        }
        std::cerr << d.format();
        return kInputError;
      }
      lsys::DeriveOptions o;
      o.steps = grammar.steps;
      o.seed = grammar.seed;
      o.max_modules = grammar.max_modules;
      o.progress = progress;
      auto grown = grow(*g, o, input, grammar.defines, {&cpu_light_oracle()});
      if (!grown) {
        if (grown.cancelled()) return kInterrupted;
        std::cerr << grown.error().format();
        return kInputError;
      }
      skeleton = std::move(grown->skeleton);
      passes.push_back({"grow", seconds_since(start), std::to_string(grown->modules) + " modules"});
    }
    if (auto problem = plant_extent_problem(skeleton)) {
      std::cerr << file_diagnostic(input, *problem).format();
      return kInputError;
    }
    scene = default_scene_for(skeleton, width.value_or(1024), height.value_or(768));
  }
  if (width) scene.width = *width;
  if (height) scene.height = *height;
  return scene;
}

std::optional<std::string> empty_plants_warning(const Scene& scene, const std::string& input) {
  size_t empty = 0, first = 0;
  for (size_t i = scene.plants.size(); i-- > 0;) {
    const ScenePlant& p = scene.plants[i];
    if (p.skeleton && p.skeleton->segment_count() == 0 && p.skeleton->leaves.empty()) ++empty, first = i;
  }
  if (empty == 0) return std::nullopt;
  const std::string nothing = ": nothing of " + std::string(empty == 1 ? "it" : "them") + " is drawn";
  if (scene.plants.size() == 1) return input + ": warning: the plant has no segments and no leaves" + nothing;
  const ScenePlant& p = scene.plants[first];
  const std::string key = p.scatter ? "scatter[" + std::to_string(p.scatter - 1) + "]"
                                    : "plants[" + std::to_string(first) + "]";  // the file's come first
  const std::string name = p.grammar.empty() ? "" : ", " + std::filesystem::path(p.grammar).filename().string();
  return input + ": warning: " + std::to_string(empty) + " of " + std::to_string(scene.plants.size()) +
         (empty == 1 ? " plants has" : " plants have") + " no segments and no leaves (the first: " + key + name + ")" +
         nothing;
}

}  // namespace sylva::cli
