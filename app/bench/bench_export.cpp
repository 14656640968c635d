// bench_export.cpp — `sylva bench export`: what the engine-ready glTF variants cost (issue 29
// §5; docs/benchmarks.md "glTF for engines"): for each input plant (default: the elm and the
// elm in leaf), `export_gltf` with the mesh alone, then the wind rig, the rig and its clip,
// the shader wind data, 3 levels of detail, everything together, and everything compressed
// with EXT_meshopt_compression; and a 1,000-tree
// instanced scatter of 10 distinct elms with 3 levels of detail. Per row: the export's CPU
// time (process CPU seconds: the impostor cards render on every core) and wall time, the
// file's bytes, its triangles per level, the rig's joints. Growing the plants is not timed.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "app/bench/bench.h"
#include "app/front/args.h"
#include "app/front/impostor.h"
#include "app/front/light.h"
#include "core/geometry/crotch_mesh.h"
#include "core/geometry/leaf_mesh.h"
#include "core/geometry/skin.h"
#include "core/geometry/tessellate.h"
#include "core/grow/grow.h"
#include "core/util/clock.h"
#include "core/io/gltf.h"
#include "core/io/gltf_lod.h"
#include "core/io/gltf_rig.h"
#include "core/scene/scene_json.h"
#include "core/util/file_io.h"

namespace sylva::cli {

namespace {

void print_help() {
  std::cout << "usage: sylva bench export [INPUT...] [--scatter N] [--quick] [--csv FILE]\n\n"
               "The cost of the engine-ready glTF variants (docs/gltf.md): each INPUT plant (a grammar, or a\n"
               "preset name looked up as presets/NAME.lsys; default: elm and elm_in_leaf) exported with the\n"
               "mesh alone, +rig, +rig +animation, +wind-data, +lod 3, all of them, and all with --compress\n"
               "meshopt, and an instanced\n"
               "scatter of N elms (10 distinct, default 1000) with 3 levels of detail. Per row: CPU and wall\n"
               "seconds of the export (growing not counted), file bytes, triangles of LOD0 and of each\n"
               "further level, rig joints.\n\n"
               "  --scatter N   trees in the scatter row (0: none; default 1000)\n"
               "  --quick       the elm and a 20-tree scatter (for tests)\n"
               "  --csv FILE    the table as CSV (default bench_export.csv)\n";
}

struct Variant {
  const char* name;
  bool rig = false, animation = false, wind_data = false;
  uint32_t lod = 0;
  bool meshopt = false;
};

const Variant kVariants[] = {
    {"mesh"}, {"rig", true}, {"rig+animation", true, true}, {"wind-data", false, false, true},
    {"lod3", false, false, false, 3}, {"all", true, true, true, 3}, {"all+meshopt", true, true, true, 3, true},
};

struct Row {
  std::string input, variant;
  double cpu_s = 0, wall_s = 0;
  uintmax_t bytes = 0;
  std::string triangles;  // per level, "38646/8408/3123/4"
  size_t joints = 0;
};

// Triangles of a plant's levels as the export writes them (the full mesh with the fillets
// an asset carries, crotch_mesh.h asset_fillets; the cards: 2 a card).
std::string level_triangles(const Skeleton& sk, uint32_t lod) {
  auto count = [](const Skeleton& s, int columns, bool fillets) {
    TessellateOptions options;
    options.segments_around = columns;
    LeafMesh leaves;
    append_leaves(leaves, s, 0);
    const SkinnedSkeleton skinned = skin_skeleton(s);
    return tessellate(skinned, options).triangle_count() + leaves.triangle_count() +
           (fillets ? asset_fillets(s, skinned.frusta).triangle_count() : 0);
  };
  std::string out = std::to_string(count(sk, 8, SkinOptions{}.blend_crotches));
  const std::vector<Skeleton> levels = lod > 1 ? lod_skeletons(sk, lod - 1, 8) : std::vector<Skeleton>();
  for (uint32_t level = 1; level < lod; ++level)
    out += "/" + std::to_string(count(levels[level - 1], lod_columns(8, level), false));
  if (lod > 0) out += "/4";
  return out;
}

// One export of `plants` timed; false (the error printed) when it fails.
bool timed_export(const std::vector<GltfPlant>& plants, const GltfExportOptions& options, const std::string& path,
                  Row& row) {
  const double cpu = process_cpu_seconds();
  const auto wall = std::chrono::steady_clock::now();
  Status exported = export_gltf(plants, path, options);
  row.cpu_s = process_cpu_seconds() - cpu;
  row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  if (!exported) {
    std::cerr << exported.error().format();
    return false;
  }
  std::error_code ec;
  row.bytes = std::filesystem::file_size(path, ec);
  return true;
}

}  // namespace

int run_bench_export(const std::vector<std::string>& args) {
  bool help = false, quick = false;
  std::string csv = "bench_export.csv";
  std::vector<std::string> inputs;
  uint64_t scatter = 1000;
  bool scatter_given = false;
  FlagTable table;
  table.flags = {help_at_once(help), set_flag({"--quick"}, quick), text_flag({"--csv"}, csv),
                 noting_given(value_flag({"--scatter"},
                                         [&scatter](const std::string&, const std::string& v) {
                                           const auto n = parse_u64(v);
                                           if (!n || *n > 100000)
                                             throw UsageError{"--scatter " + v + ": expected an integer from 0 to 100000"};
                                           scatter = *n;
                                         }),
                              scatter_given)};
  table.positional = [&inputs](const std::string& a) { inputs.push_back(a); };
  parse_flags(std::span(args).subspan(1), table);  // args[0] is "export"
  if (help) {
    print_help();
    return kOk;
  }
  const std::string presets = SYLVA_PRESETS_DIR;
  if (inputs.empty()) inputs = quick ? std::vector<std::string>{"elm"} : std::vector<std::string>{"elm", "elm_in_leaf"};
  if (quick && !scatter_given) scatter = 20;
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / ("sylva-bench-export-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  std::vector<Row> rows;
  std::printf("%-14s %-14s %8s %8s %11s %6s  %s\n", "input", "variant", "cpu_s", "wall_s", "bytes", "joints",
              "triangles per level");
  auto print = [](const Row& r) {
    std::printf("%-14s %-14s %8.3f %8.3f %11ju %6zu  %s\n", r.input.c_str(), r.variant.c_str(), r.cpu_s, r.wall_s,
                r.bytes, r.joints, r.triangles.c_str());
    std::fflush(stdout);
  };
  for (const std::string& input : inputs) {
    const std::string path = std::filesystem::exists(input) ? input : presets + "/" + input + ".lsys";
    auto grammar = lsys::load_grammar(path);
    if (!grammar) {
      std::cerr << grammar.error().format();
      return kInputError;
    }
    auto grown = grow(*grammar, {}, path, {}, {&cpu_light_oracle()});
    if (!grown) {
      std::cerr << grown.error().format();
      return kInputError;
    }
    GltfPlant plant;
    plant.name = std::filesystem::path(path).stem().string();
    plant.skeleton = std::move(grown->skeleton);
    for (const Variant& v : kVariants) {
      GltfExportOptions options;
      options.mesh = true;
      options.extras = GltfExtras::compact;
      options.rig = v.rig;
      options.wind_data = v.wind_data;
      options.lod = v.lod;
      if (v.animation) options.animation = GltfWindClip{};
      if (v.lod) options.card_renderer = cpu_card_renderer({});
      if (v.meshopt) options.compress = GltfCompression::meshopt;
      Row row;
      row.input = plant.name;
      row.variant = v.name;
      if (!timed_export({plant}, options, (folder / (plant.name + "_" + v.name + ".glb")).string(), row)) return kInputError;
      row.triangles = level_triangles(plant.skeleton, v.lod);
      if (v.rig) row.joints = build_rig(plant.skeleton)->joints.size();
      print(row);
      rows.push_back(std::move(row));
    }
  }
  if (scatter > 0) {
    const std::string text = R"({"format":"sylva-scene","version":1,"plants":[],"scatter":[{"grammar":")" + presets +
                             R"(/elm.lsys","count":)" + std::to_string(scatter) +
                             R"(,"disc":{"centre":[0,0],"radius":)" + std::to_string(4 * std::sqrt(double(scatter))) +
                             R"(},"seed":1,"plant_seeds":[1,10],"rotate_y_deg":[0,360],"scale":[0.8,1.2],"min_spacing":2}]})";
    Expected<Scene> scene = parse_scene_json(text, "scatter.scene.json", presets);
    if (!scene) {
      std::cerr << scene.error().format();
      return kInputError;
    }
    if (Status grown = grow_scene_plants(*scene, 50'000'000, {}, &cpu_light_oracle()); !grown) {
      std::cerr << grown.error().format();
      return kInputError;
    }
    std::vector<GltfPlant> plants;
    for (ScenePlant& sp : scene->plants) {
      GltfPlant p;
      p.name = "elm";
      p.skeleton = std::move(*sp.skeleton);
      for (int k = 0; k < 3; ++k) p.position_m[k] = sp.position[k];
      p.rotate_y_deg = sp.rotate_y_deg;
      p.scale = sp.scale;
      plants.push_back(std::move(p));
    }
    GltfExportOptions options;
    options.mesh = true;
    options.extras = GltfExtras::compact;
    options.instancing = true;
    options.lod = 3;
    options.card_renderer = cpu_card_renderer({});
    Row row;
    row.input = "scatter" + std::to_string(scatter);
    row.variant = "instanced+lod3";
    if (!timed_export(plants, options, (folder / "scatter.glb").string(), row)) return kInputError;
    row.triangles = "10 distinct elms";
    print(row);
    rows.push_back(std::move(row));
  }
  std::error_code ec;
  std::filesystem::remove_all(folder, ec);
  std::string out = "input,variant,cpu_s,wall_s,bytes,joints,triangles\n";
  for (const Row& r : rows) {
    char line[256];
    std::snprintf(line, sizeof line, "%s,%s,%.4f,%.4f,%ju,%zu,%s\n", r.input.c_str(), r.variant.c_str(), r.cpu_s,
                  r.wall_s, r.bytes, r.joints, r.triangles.c_str());
    out += line;
  }
  if (Status written = write_file_atomically(csv, out); !written) {
    std::cerr << written.error().format();
    return kInputError;
  }
  std::cerr << "sylva bench export: wrote " << csv << "\n";
  return kOk;
}

}  // namespace sylva::cli
