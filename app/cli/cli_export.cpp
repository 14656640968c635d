// cli_export.cpp — `sylva export INPUT -o FILE.gltf|FILE.glb [--mesh] [--segments-around N]`
// (docs/spec/cli.md): a grammar, skeleton or scene to glTF 2.0 with the skeleton in the
// node extras (core/io/gltf.h; `--extras compact|full|none`, compact by default:
// docs/gltf.md); `--seed A..B` with `-o out/p_{seed}.glb` exports a
// batch in parallel (app/batch.h). The mesh's bark comes from each plant of a scene, or
// for a grammar or skeleton from the --bark-* flags (docs/spec/scene.md's bark keys as flags).
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "app/front/light.h"
#include "app/front/batch.h"
#include "app/front/impostor.h"
#include "app/cli/cli.h"
#include "core/grow/grow.h"
#include "core/io/gltf.h"
#include "core/scene/scene.h"
#include "core/geometry/skeleton.h"
#include "core/grow/turtle.h"
#include "core/scene/scene_json.h"

namespace sylva::cli {

namespace {

void print_export_help() {
  std::cout << "usage: sylva export INPUT -o FILE.gltf|FILE.glb [--mesh] [--segments-around N] [--instancing]\n"
               "                    [--rig [--max-joints N]] [--animation] [--wind-data] [--lod N]\n"
               "                    [--compress meshopt]\n"
               "                    [--extras compact|full|none] [--skin smooth|paper]\n"
               "                    [--bark-albedo FILE] [--bark-height FILE] [--relief-depth M]\n"
               "                    [--u-repeat N] [--v-per-metre N]\n"
               "                    [-n STEPS] [--seed S|A..B] [-D NAME=VALUE]... [--max-modules N]\n\n"
               "Writes glTF 2.0 (Y up, metres; .glb binary or .gltf with embedded data), atomically.\n"
               "Each plant is a node named after its grammar with the skeleton as a LINES mesh\n"
               "(POSITION, _RADIUS) and the exact skeleton, seed and skinning data in the node's\n"
               "extras.sylva. INPUT is a .lsys grammar, a .skel.json skeleton or a .scene.json scene.\n"
               "Prints one summary line per file written: INPUT -> FILE, plants, chains, segments,\n"
               "bytes, time.\n\n"
               "  -o, --output FILE        the .gltf or .glb file to write\n"
               "      --mesh               also write the skinned frusta as a triangle mesh: normals,\n"
               "                           TEXCOORD_0 = (turns around * u_repeat, metres along *\n"
               "                           v_per_metre), one material per material index\n"
               "      --segments-around N  columns around each frustum of the mesh, 3 to 4096 (default 8)\n"
               "      --instancing         repeated identical plants of a scene as one node with\n"
               "                           EXT_mesh_gpu_instancing\n"
               "      --rig                skin the mesh to a glTF skin for wind (needs --mesh, not with\n"
               "                           --instancing): joints along the first branch orders, a joint\n"
               "                           every k internodes, each vertex on at most 2 (docs/gltf.md)\n"
               "      --max-joints N       the rig's joints per plant, root included, 1 to 1024 (default 128)\n"
               "      --animation          with --rig: the scene's animation (or the default sway) as one\n"
               "                           looping clip 'wind' of joint rotations, frequencies rounded to\n"
               "                           whole cycles per duration_s\n"
               "      --wind-data          per-vertex wind data for shaders (needs --mesh): TEXCOORD_2 =\n"
               "                           (pivot x, pivot y), TEXCOORD_3 = (pivot z, level + phase)\n"
               "      --lod N              levels of detail NAME_LOD0 ... NAME_LODN (needs --mesh), N from 1\n"
               "                           to 6: each re-meshed from the skeleton with about a quarter\n"
               "                           of the triangles before, the last two crossed impostor cards\n"
               "                           drawn by the CPU ray caster (docs/gltf.md)\n"
               "      --compress meshopt   encode the vertex and index data with EXT_meshopt_compression\n"
               "                           (lossless; then required: three.js, Babylon and glTFast\n"
               "                           decode it, Blender 3.4 and Godot cannot); default: none\n"
               "      --skin S             how chains meet in the mesh and extras' skinning, for every\n"
               "                           plant (over a scene's skin keys): smooth (the default) or\n"
               "                           paper (Bhagvat et al. 2009's mitred chains)\n"
               "      --extras MODE        how each node's extras.sylva holds the skeleton (docs/gltf.md):\n"
               "                           compact (default) the large arrays (joints, chains, leaves,\n"
               "                             skinning, instance placements) as raw little-endian float64/\n"
               "                             uint32 bufferViews referenced by index: bit-exact, small;\n"
               "                           full  every number as JSON text (as files written before);\n"
               "                           none  no skeleton: a plain mesh that 'sylva render' cannot read\n"
               "                           back. 'sylva render FILE' reads compact and full files.\n"
               "Bark of the mesh (a scene gives each plant's own; these are for a .lsys or .skel.json\n"
               "INPUT and need --mesh):\n"
               "      --bark-albedo FILE   albedo texture (PNG or JPEG, sRGB), embedded as baseColorTexture\n"
               "      --bark-height FILE   height map (1 = outermost, 0 = furrow bottom), baked into a\n"
               "                           tangent-space normalTexture at the plant's median radius\n"
               "      --relief-depth M     relief depth in metres, >= 0 (default 0.02)\n"
               "      --u-repeat N         texture repeats around the stem, > 0 (default 1)\n"
               "      --v-per-metre N      texture repeats per metre along the stem, > 0 (default 1)\n"
               "  A missing or unreadable texture is an error (exit 1); nothing is written.\n"
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

// The node name of a plant: the file name without folder and extension(s).
std::string plant_name(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  for (std::string_view ext : {".lsys", ".skel.json", ".json"})
    if (name.ends_with(ext) && name.size() > ext.size()) {
      name.resize(name.size() - ext.size());
      break;
    }
  return name;
}

enum class InputKind { grammar, skeleton, scene };

// The wind clip of a scene's `animation` key (docs/animation.md): its sway, duration and fps.
GltfWindClip wind_clip_of(const SceneAnimation& animation) {
  return {.sway = sway_parameters_of(animation), .duration_s = animation.duration_s, .fps = animation.fps};
}

// A finite number from `text`, in (lo, hi] or [lo, hi] (`open_low`); a usage error naming `name`.
double number_flag(const std::string& name, const std::string& text, double lo, bool open_low) {
  double v = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  const bool ok = ec == std::errc() && ptr == text.data() + text.size() && std::isfinite(v) && v <= 1e6 &&
                  (open_low ? v > lo : v >= lo);
  if (!ok)
    throw UsageError{name + " " + text + ": expected a number " + (open_low ? "> " : ">= ") +
                     (lo == 0 ? "0" : std::to_string(lo)) + " and <= 1e6"};
  return v;
}

// The one summary line export prints on stdout, like grow's: what was read, what was
// written, its plants, chains and segments (and leaves, where there are any), the file's
// size and the time taken.
std::string export_summary(const std::string& input, const std::string& output, const std::vector<GltfPlant>& plants,
                           std::chrono::steady_clock::time_point start) {
  size_t chains = 0, segments = 0, leaves = 0;
  for (const GltfPlant& p : plants)
    chains += p.skeleton.chains.size(), segments += p.skeleton.segment_count(), leaves += p.skeleton.leaves.size();
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(output, ec);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  char time[32];
  std::snprintf(time, sizeof time, "%.4g", ms);
  return input + " -> " + output + ": " + std::to_string(plants.size()) + (plants.size() == 1 ? " plant, " : " plants, ") +
         std::to_string(chains) + " chains, " + std::to_string(segments) + " segments, " +
         (leaves ? std::to_string(leaves) + (leaves == 1 ? " leaf, " : " leaves, ") : std::string()) +
         (ec ? std::string("? bytes") : std::to_string(bytes) + " bytes") + ", " + time + " ms";
}

}  // namespace

int run_export(const std::vector<std::string>& raw_args) {
  // The export flags first; what is left is the grammar flags' business.
  GltfExportOptions options;
  options.extras = GltfExtras::compact;  // the CLI's default (the library's is full)
  Bark bark;                 // from the --bark-* flags
  std::optional<SkinStyle> skin;  // --skin
  bool bark_flags = false;
  bool animation = false;     // --animation
  bool max_joints_given = false;
  FlagTable table;
  table.inline_values = InlineValues::value_flags;
  table.leaves_others = true;  // INPUT, -o and the grammar flags: parse_grammar_args's
  table.later_value_flags = grammar_value_flags();
  // A --bark-* flag: `set` stores its value in `bark`; bark_flags says one was given.
  auto bark_flag = [&bark_flags](const std::string& name, std::function<void(const std::string& value)> set) {
    return noting_given(value_flag({name}, [set = std::move(set)](const std::string&, const std::string& value) {
                          set(value);
                        }),
                        bark_flags);
  };
  table.flags = {
      bark_flag("--bark-albedo", [&bark](const std::string& v) { bark.albedo_texture = v; }),
      bark_flag("--bark-height", [&bark](const std::string& v) { bark.height_texture = v; }),
      bark_flag("--relief-depth",
                [&bark](const std::string& v) { bark.relief_depth_m = number_flag("--relief-depth", v, 0, false); }),
      bark_flag("--u-repeat", [&bark](const std::string& v) { bark.u_repeat = number_flag("--u-repeat", v, 0, true); }),
      bark_flag("--v-per-metre",
                [&bark](const std::string& v) { bark.v_per_metre = number_flag("--v-per-metre", v, 0, true); }),
      set_flag({"--mesh"}, options.mesh),
      skin_flag(skin),
      set_flag({"--instancing"}, options.instancing),
      set_flag({"--rig"}, options.rig),
      set_flag({"--animation"}, animation),
      set_flag({"--wind-data"}, options.wind_data),
      value_flag({"--compress"},
                 [&options](const std::string&, const std::string& v) {
                   if (v == "meshopt") options.compress = GltfCompression::meshopt;
                   else if (v == "none") options.compress = GltfCompression::none;
                   else throw UsageError{"--compress " + v + ": expected meshopt or none"};
                 }),
      value_flag({"--lod"},
                 [&options](const std::string&, const std::string& v) {
                   const auto n = parse_u64(v);
                   if (!n || *n < 1 || *n > kMaxLodLevels)
                     throw UsageError{"--lod " + v + ": expected an integer from 1 to " + std::to_string(kMaxLodLevels)};
                   options.lod = static_cast<uint32_t>(*n);
                 }),
      noting_given(value_flag({"--max-joints"},
                              [&options](const std::string&, const std::string& v) {
                                const auto n = parse_u64(v);
                                if (!n || *n < 1 || *n > kMaxRigJoints)
                                  throw UsageError{"--max-joints " + v + ": expected an integer from 1 to " +
                                                   std::to_string(kMaxRigJoints)};
                                options.max_joints = static_cast<uint32_t>(*n);
                              }),
                   max_joints_given),
      value_flag({"--extras"},
                 [&options](const std::string&, const std::string& mode) {
                   if (mode == "compact") options.extras = GltfExtras::compact;
                   else if (mode == "full") options.extras = GltfExtras::full;
                   else if (mode == "none") options.extras = GltfExtras::none;
                   else throw UsageError{"--extras " + mode + ": expected compact, full or none"};
                 }),
      value_flag({"--segments-around"},
                 [&options](const std::string&, const std::string& v) {
                   const auto n = parse_u64(v);
                   if (!n || *n < 3 || *n > 4096)
                     throw UsageError{"--segments-around " + v + ": expected an integer from 3 to 4096"};
                   options.segments_around = static_cast<int>(*n);
                 }),
  };
  std::vector<std::string> args = parse_flags(raw_args, table);
  const std::optional<SeedRange> range = take_seed_range(args, grammar_value_flags());
  const GrammarArgs a = parse_grammar_args(
      args, {.wants_output = true,
             .missing_input = "missing INPUT (a .lsys grammar, a .skel.json skeleton or a .scene.json scene)",
             .missing_output = "missing -o FILE.gltf|FILE.glb"});
  if (a.help) {
    print_export_help();
    return kOk;
  }
  const auto start = std::chrono::steady_clock::now();
  const std::string& input = a.grammar;
  InputKind kind;
  if (input.ends_with(".skel.json")) kind = InputKind::skeleton;
  else if (input.ends_with(".scene.json")) kind = InputKind::scene;
  else if (lsys::is_grammar_path(input)) kind = InputKind::grammar;
  else throw UsageError{"INPUT '" + input + "' must be a grammar (.lsys, a cpfg .l or a vlab object), a .skel.json skeleton or a .scene.json scene"};
  if (!a.output.ends_with(".gltf") && !a.output.ends_with(".glb"))
    throw UsageError{"-o " + a.output + ": the output must end in .gltf or .glb"};
  if (kind != InputKind::grammar && (a.steps || a.seed || range || !a.defines.empty()))
    throw UsageError{"-n, --seed and -D apply to a .lsys INPUT only"};
  if (bark_flags && kind == InputKind::scene)
    throw UsageError{"--bark-albedo, --bark-height, --relief-depth, --u-repeat and --v-per-metre apply to a .lsys or "
                     ".skel.json INPUT only (a scene gives each plant's bark)"};
  if (bark_flags && !options.mesh)
    throw UsageError{"--bark-albedo, --bark-height, --relief-depth, --u-repeat and --v-per-metre shape the mesh: "
                     "add --mesh"};
  if (options.rig && !options.mesh) throw UsageError{"--rig skins the mesh: add --mesh"};
  if (options.rig && options.instancing)
    throw UsageError{"--rig and --instancing cannot be combined: glTF instancing (EXT_mesh_gpu_instancing) does not "
                     "skin"};
  if (max_joints_given && !options.rig) throw UsageError{"--max-joints sizes the rig: add --rig"};
  if (animation && !options.rig) throw UsageError{"--animation poses the rig: add --rig"};
  if (options.wind_data && !options.mesh) throw UsageError{"--wind-data is per mesh vertex: add --mesh"};
  if (options.lod > 0 && !options.mesh) throw UsageError{"--lod re-meshes the plant: add --mesh"};
  if (options.lod > 0) options.card_renderer = cpu_card_renderer({});
  // The default sway; a scene's own `animation` key replaces it below.
  if (animation) options.animation = wind_clip_of(SceneAnimation{});
  if (range && !has_seed_placeholder(a.output))
    throw UsageError{"--seed " + std::to_string(range->first) + ".." + std::to_string(range->last) +
                     " writes one file per seed: -o must hold {seed}, e.g. -o out/plant_{seed}.glb"};
  if (range) check_pattern_separates(a.output, "{seed}");

  // The textures are checked once, before any plant grows or any file is written.
  if (Status textures = check_bark_textures(bark); !textures) {
    std::cerr << textures.error().format();
    return kInputError;
  }

  if (kind == InputKind::skeleton) {
    Expected<Skeleton> read = read_skeleton_file(input);
    if (!read) {
      std::cerr << read.error().format();
      return kInputError;
    }
    GltfPlant plant;
    plant.name = plant_name(input);
    plant.skeleton = std::move(*read);
    plant.bark = bark;
    plant.skin = skin.value_or(SkinStyle::smooth);
    if (Status exported = export_gltf({plant}, a.output, options); !exported) {
      std::cerr << exported.error().format();
      return kInputError;
    }
    std::cout << export_summary(input, a.output, {plant}, start) << "\n";
    return kOk;
  }
  if (kind == InputKind::scene) {
    Expected<Scene> read = read_scene_file(input);
    if (!read) {
      std::cerr << read.error().format();
      return kInputError;
    }
    Scene& scene = *read;
    if (skin) override_skin(scene, *skin);
    if (animation && scene.animation) options.animation = wind_clip_of(*scene.animation);
    if (scene.animation) options.wind_seed = scene.animation->seed;
    // A plant's grammar error: the grammar's place, and a note at the scene key naming it.
    if (Status grown = grow_scene_plants(scene, a.max_modules, {}, &cpu_light_oracle()); !grown) {
      std::cerr << grown.error().format();
      return kInputError;
    }
    // One glTF material per entry (docs/materials.md), the plants' vlab colours included.
    options.materials = scene.materials;
    if (options.lod > 0) options.card_renderer = cpu_card_renderer(scene.materials);
    std::vector<GltfPlant> plants;
    for (ScenePlant& sp : scene.plants) {
      GltfPlant p;
      p.name = plant_name(sp.grammar.empty() ? input : sp.grammar);
      p.skeleton = std::move(*sp.skeleton);
      for (int k = 0; k < 3; ++k) p.position_m[k] = sp.position[k];
      p.rotate_y_deg = sp.rotate_y_deg;
      p.scale = sp.scale;
      p.bark = sp.bark;
      p.skin = sp.skin;
      plants.push_back(std::move(p));
    }
    if (Status exported = export_gltf(plants, a.output, options); !exported) {
      std::cerr << exported.error().format();
      return kInputError;
    }
    std::cout << export_summary(input, a.output, plants, start) << "\n";
    return kOk;
  }

  int code = kOk;
  auto g = load_grammar_for(a, &code);
  if (!g) return code;
  // A vlab object's colour map or material file: its colours as the glTF materials.
  add_grammar_colours(g->colours, options.materials);
  if (options.lod > 0) options.card_renderer = cpu_card_renderer(options.materials);
  // Grows with `one`'s seed and exports to `output`.
  // Grows with `one`'s seed and exports to `output`; the summary line on success.
  auto export_one = [&](const GrammarArgs& one, const std::string& output) -> Expected<std::string> {
    const auto one_start = std::chrono::steady_clock::now();
    auto grown = grow(*g, derive_options_for(one), one.grammar, one.defines, {&cpu_light_oracle()});
    if (!grown) return std::move(grown.error());
    GltfPlant plant;
    plant.name = plant_name(input);
    plant.skeleton = std::move(grown->skeleton);
    plant.bark = bark;
    plant.skin = skin.value_or(SkinStyle::smooth);
    if (Status exported = export_gltf({plant}, output, options); !exported) return std::move(exported.error());
    return export_summary(input, output, {plant}, one_start);
  };
  if (range) {
    if (Status folder = create_parent_folder(expand_seed_pattern(a.output, range->first)); !folder) {
      std::cerr << folder.error().format();
      return kInputError;
    }
    return run_seed_batch("export", *range, [&](uint64_t seed) {
      GrammarArgs one = a;
      one.seed = seed;
      SeedTaskResult r;
      Expected<std::string> output = seed_output_path(a.output, seed);
      if (!output)
        r.error = std::move(output.error());
      else if (Expected<std::string> exported = export_one(one, *output); !exported)
        r.error = std::move(exported.error());
      else
        r.summary = std::move(*exported);
      return r;
    });
  }
  Expected<std::string> output = has_seed_placeholder(a.output) && a.seed ? seed_output_path(a.output, *a.seed)
                                                                          : Expected<std::string>(a.output);
  if (!output) {
    std::cerr << output.error().format();
    return kInputError;
  }
  Expected<std::string> exported = export_one(a, *output);
  if (!exported) {
    std::cerr << exported.error().format();
    return kInputError;
  }
  std::cout << *exported << "\n";
  return kOk;
}

}  // namespace sylva::cli
