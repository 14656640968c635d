// render_input.cpp — see render_input.h.
#include "app/front/render_input.h"

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <glm/common.hpp>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include "core/io/gltf.h"
#include "core/scene/render_common.h"
#include "core/grow/turtle.h"
#include "core/scene/scene_json.h"
#include "core/util/json.h"
#include "core/grow/grow.h"
#include "core/util/clock.h"
#include "core/util/file_io.h"
#include "app/front/light.h"

namespace sylva::cli {

bool is_grammar_input(const std::string& path) { return lsys::is_grammar_path(path); }

namespace {

// A private folder under the temporary directory, removed with everything in it when the
// last scene holding it goes.
class ScratchFolder {
 public:
  static Expected<std::shared_ptr<ScratchFolder>> make() {
    std::error_code ec;  // $TMPDIR naming no folder: /tmp, as mkdtemp(3) users expect
    std::filesystem::path base = std::filesystem::temp_directory_path(ec);
    if (ec) base = "/tmp";
    std::string pattern = (base / "sylva-gltf-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
      return file_diagnostic(pattern, std::string("cannot make a folder for the file's images: ") + std::strerror(errno));
    return std::make_shared<ScratchFolder>(pattern);
  }
  explicit ScratchFolder(std::string path) : path_(std::move(path)) {}
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The bark height map a glTF's material names (the path `sylva export` was given): as
// given (absolute, or from the working folder), else beside the glTF file; none if neither
// is a file.
std::optional<std::string> find_height_map(const std::string& given, const std::string& gltf_path) {
  std::error_code e;
  const std::filesystem::path as_given(given);
  if (std::filesystem::is_regular_file(as_given, e)) return given;
  if (as_given.is_relative()) {
    const std::filesystem::path beside = std::filesystem::path(gltf_path).parent_path() / as_given;
    if (std::filesystem::is_regular_file(beside, e)) return beside.string();
    const std::filesystem::path by_name = std::filesystem::path(gltf_path).parent_path() / as_given.filename();
    if (std::filesystem::is_regular_file(by_name, e)) return by_name.string();
  }
  return std::nullopt;
}

// Gives the plants of a glTF file the looks the file carries (GltfLook, core/io/gltf.h):
// each plant's bark (its albedo image written to a scratch folder the scene holds, its
// height map where the path the export was given still leads to one) and the scene's
// materials (the first plant that uses an index sets it). Warns on stderr for a height map
// that cannot be found: the plant is drawn without relief.
Status apply_gltf_looks(const std::vector<GltfPlant>& imported, const std::string& input, Scene& scene) {
  std::shared_ptr<ScratchFolder> folder;
  std::map<const std::string*, std::string> written;  // image bytes -> its file
  auto file_of = [&](const GltfLook::Image& image) -> Expected<std::string> {
    if (auto found = written.find(image.bytes.get()); found != written.end()) return found->second;
    if (!folder) {
      Expected<std::shared_ptr<ScratchFolder>> made = ScratchFolder::make();
      if (!made) return std::move(made.error());
      folder = *made;
      scene.files_held = folder;
    }
    const std::string file = folder->path() + "/image" + std::to_string(written.size()) +
                             (image.mime == "image/jpeg" ? ".jpg" : ".png");
    if (Status saved = write_file_atomically(file, *image.bytes); !saved) return std::move(saved.error());
    return written.emplace(image.bytes.get(), file).first->second;
  };
  std::set<std::string> missing_heights;
  for (size_t i = 0; i < imported.size(); ++i) {
    if (!imported[i].look) continue;
    const GltfLook& look = *imported[i].look;
    Bark& bark = scene.plants[i].bark;
    bark = look.bark;
    if (look.bark_albedo) {
      Expected<std::string> file = file_of(*look.bark_albedo);
      if (!file) return std::move(file.error());
      bark.albedo_texture = *file;
      bark.albedo_rgb.reset();
    }
    if (look.bark_height) {
      bark.height_texture = find_height_map(*look.bark_height, input);
      if (!bark.height_texture) missing_heights.insert(*look.bark_height);
    }
    for (const GltfLook::Material& m : look.materials) {
      if (scene.materials.count(m.index)) continue;
      SceneMaterial material = m.material;
      if (m.image) {
        Expected<std::string> file = file_of(*m.image);
        if (!file) return std::move(file.error());
        material.albedo_image = *file;
      }
      scene.materials.emplace(m.index, std::move(material));
    }
  }
  for (const std::string& height : missing_heights)
    std::cerr << input << ": warning: the bark's height map '" << height
              << "' (the file holds only the normal map baked from it) is neither where the export found it nor "
                 "beside the file: the bark is drawn without relief\n";
  return {};
}

}  // namespace

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
    if (Status looks = apply_gltf_looks(*imported, input, scene); !looks) {
      std::cerr << looks.error().format();
      return kInputError;
    }
    passes.push_back({"read glTF", seconds_since(start), std::to_string(scene.plants.size()) + " plants"});
  } else {
    Skeleton skeleton;
    std::map<uint32_t, SceneMaterial> colours;
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
      add_grammar_colours(g->colours, colours);  // a vlab object's colour map or material file
      passes.push_back({"grow", seconds_since(start), std::to_string(grown->modules) + " modules"});
    }
    if (auto problem = plant_extent_problem(skeleton)) {
      std::cerr << file_diagnostic(input, *problem).format();
      return kInputError;
    }
    scene = default_scene_for(skeleton, width.value_or(1024), height.value_or(768));
    if (!colours.empty()) scene.materials = std::move(colours);
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
