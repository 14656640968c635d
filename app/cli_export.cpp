// cli_export.cpp — `sylva export INPUT -o FILE.gltf|FILE.glb [--mesh] [--segments-around N]`
// (cli.md, issue 5): a grammar, skeleton or scene to glTF 2.0 with the skeleton in the
// node extras (core/gltf_export.h); `--seed A..B` with `-o out/p_{seed}.glb` exports a
// batch in parallel (app/batch.h).
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "app/batch.h"
#include "app/cli.h"
#include "core/gltf_export.h"
#include "core/scene.h"
#include "core/skeleton.h"
#include "core/turtle.h"

namespace sylva::cli {

namespace {

void print_export_help() {
  std::cout << "usage: sylva export INPUT -o FILE.gltf|FILE.glb [--mesh] [--segments-around N] [--instancing]\n"
               "                    [-n STEPS] [--seed S|A..B] [-D NAME=VALUE]... [--max-modules N]\n\n"
               "Writes glTF 2.0 (Y up, metres; .glb binary or .gltf with embedded data), atomically.\n"
               "Each plant is a node named after its grammar with the skeleton as a LINES mesh\n"
               "(POSITION, _RADIUS) and the exact skeleton, seed and skinning data in the node's\n"
               "extras.sylva. INPUT is a .lsys grammar, a .skel.json skeleton or a .scene.json scene.\n\n"
               "  -o, --output FILE        the .gltf or .glb file to write\n"
               "      --mesh               also write the skinned frusta as a triangle mesh (normals,\n"
               "                           TEXCOORD_0 = u in turns, v in metres) with a bark material\n"
               "      --segments-around N  columns around each frustum of the mesh, 3 to 4096 (default 8)\n"
               "      --instancing         repeated identical plants of a scene as one node with\n"
               "                           EXT_mesh_gpu_instancing\n"
               "For a .lsys INPUT:\n"
               "  -n, --steps N            derivation steps (overrides 'derivation length:')\n"
               "      --seed S             random seed, an integer from 0 to 2^64-1 (overrides 'seed:')\n"
               "      --seed A..B          a batch: every seed from A to B, in parallel on all cores;\n"
               "                           -o must then hold {seed} (out/elm_{seed}.glb), its folder is\n"
               "                           created; a failed seed is named on stderr, the others are\n"
               "                           still written, and the exit status is 1\n"
               "  -D NAME=VALUE            override '#define NAME' (repeatable)\n"
               "      --max-modules N      stop with an error if a word would exceed N modules\n"
               "  -h, --help               show this help\n";
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The node name of a plant: the file name without folder and extension(s).
std::string plant_name(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  for (const char* ext : {".lsys", ".skel.json", ".json"})
    if (ends_with(name, ext) && name.size() > std::string(ext).size()) {
      name.resize(name.size() - std::string(ext).size());
      break;
    }
  return name;
}

enum class InputKind { grammar, skeleton, scene };

}  // namespace

int run_export(const std::vector<std::string>& raw_args) {
  // The export flags first; what is left is the grammar flags' business.
  GltfExportOptions options;
  std::vector<std::string> args;
  for (size_t i = 0; i < raw_args.size(); ++i) {
    const std::string& a = raw_args[i];
    if (a == "--mesh") {
      options.mesh = true;
    } else if (a == "--instancing") {
      options.instancing = true;
    } else if (a == "--segments-around" || a.rfind("--segments-around=", 0) == 0) {
      std::string v;
      if (a.size() > std::string("--segments-around").size()) {
        v = a.substr(std::string("--segments-around=").size());
      } else {
        if (i + 1 >= raw_args.size()) throw UsageError{"--segments-around needs a value"};
        v = raw_args[++i];
      }
      const auto n = parse_u64(v);
      if (!n || *n < 3 || *n > 4096) throw UsageError{"--segments-around " + v + ": expected an integer from 3 to 4096"};
      options.segments_around = static_cast<int>(*n);
    } else {
      args.push_back(a);
      // Keep a value that follows a value-taking flag with it, whatever it looks like.
      for (const std::string& f : grammar_value_flags())
        if (a == f && i + 1 < raw_args.size()) args.push_back(raw_args[++i]);
    }
  }
  const std::optional<SeedRange> range = take_seed_range(args, grammar_value_flags());
  GrammarArgs a;
  try {
    a = parse_grammar_args(args, true);
  } catch (const UsageError& e) {
    if (e.message.rfind("missing GRAMMAR", 0) == 0)
      throw UsageError{"missing INPUT (a .lsys grammar, a .skel.json skeleton or a .scene.json scene)"};
    if (e.message.rfind("missing -o", 0) == 0) throw UsageError{"missing -o FILE.gltf|FILE.glb"};
    throw;
  }
  if (a.help) {
    print_export_help();
    return kOk;
  }
  const std::string& input = a.grammar;
  InputKind kind;
  if (ends_with(input, ".skel.json")) kind = InputKind::skeleton;
  else if (ends_with(input, ".scene.json")) kind = InputKind::scene;
  else if (ends_with(input, ".lsys")) kind = InputKind::grammar;
  else throw UsageError{"INPUT '" + input + "' must be a .lsys grammar, a .skel.json skeleton or a .scene.json scene"};
  if (!ends_with(a.output, ".gltf") && !ends_with(a.output, ".glb"))
    throw UsageError{"-o " + a.output + ": the output must end in .gltf or .glb"};
  if (kind != InputKind::grammar && (a.steps || a.seed || range || !a.defines.empty()))
    throw UsageError{"-n, --seed and -D apply to a .lsys INPUT only"};
  if (range && !has_seed_placeholder(a.output))
    throw UsageError{"--seed " + std::to_string(range->first) + ".." + std::to_string(range->last) +
                     " writes one file per seed: -o must hold {seed}, e.g. -o out/plant_{seed}.glb"};

  if (kind == InputKind::skeleton) {
    SkeletonReadResult read = read_skeleton_file(input);
    if (!read.skeleton) {
      std::cerr << (read.error ? read.error->format() : input + ": error: unreadable skeleton") << "\n";
      return kInputError;
    }
    GltfPlant plant;
    plant.name = plant_name(input);
    plant.skeleton = std::move(*read.skeleton);
    if (auto err = export_gltf({plant}, a.output, options)) {
      std::cerr << *err << "\n";
      return kInputError;
    }
    return kOk;
  }
  if (kind == InputKind::scene) {
    SceneReadResult read = read_scene_file(input);
    if (!read.scene) {
      std::cerr << (read.error ? read.error->format() : input + ": error: unreadable scene") << "\n";
      return kInputError;
    }
    Scene& scene = *read.scene;
    if (auto err = grow_scene_plants(scene, a.max_modules)) {
      std::cerr << *err;
      if (!err->empty() && err->back() != '\n') std::cerr << "\n";
      return kInputError;
    }
    std::vector<GltfPlant> plants;
    for (ScenePlant& sp : scene.plants) {
      GltfPlant p;
      p.name = plant_name(sp.grammar.empty() ? input : sp.grammar);
      p.skeleton = std::move(*sp.skeleton);
      for (int k = 0; k < 3; ++k) p.position_m[k] = sp.position[k];
      p.rotate_y_deg = sp.rotate_y_deg;
      p.scale = sp.scale;
      plants.push_back(std::move(p));
    }
    if (auto err = export_gltf(plants, a.output, options)) {
      std::cerr << *err << "\n";
      return kInputError;
    }
    return kOk;
  }

  int code = kOk;
  auto g = load_grammar_for(a, &code);
  if (!g) return code;
  // Grows with `one`'s seed and exports to `output`; the error text or nothing.
  auto export_one = [&](const GrammarArgs& one, const std::string& output) -> std::optional<std::string> {
    auto grown = grow(*g, derive_options_for(one), one.grammar, one.defines);
    if (!grown) return grown.error().format();
    GltfPlant plant;
    plant.name = plant_name(input);
    plant.skeleton = std::move(grown->skeleton);
    return export_gltf({plant}, output, options);
  };
  if (range) {
    if (auto err = create_parent_folder(expand_seed_pattern(a.output, range->first))) {
      std::cerr << *err << "\n";
      return kInputError;
    }
    return run_seed_batch("export", *range, [&](uint64_t seed) {
      GrammarArgs one = a;
      one.seed = seed;
      SeedTaskResult r;
      r.error = export_one(one, expand_seed_pattern(a.output, seed));
      return r;
    });
  }
  const std::string output = has_seed_placeholder(a.output) && a.seed ? expand_seed_pattern(a.output, *a.seed) : a.output;
  if (auto err = export_one(a, output)) {
    std::cerr << *err;
    if (!err->empty() && err->back() != '\n') std::cerr << "\n";
    return kInputError;
  }
  return kOk;
}

}  // namespace sylva::cli
