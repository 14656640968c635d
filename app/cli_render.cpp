// cli_render.cpp — `sylva render` (cli.md, scene.md): a scene, grammar or skeleton to an
// image through the CPU ray caster (the OpenGL backend comes with the next issue).
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <glm/common.hpp>
#include <iostream>
#include <limits>

#include "app/cli.h"
#include "core/gltf_export.h"
#include "core/image_io.h"
#include "core/render_cpu.h"
#include "core/scene.h"
#include "core/turtle.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sylva::cli {

namespace {

constexpr int kInterrupted = 130;  // 128 + SIGINT, the shell's convention

std::atomic<bool> g_interrupted{false};
extern "C" void on_sigint(int) { g_interrupted.store(true); }
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT handler needs a lock-free flag");

void print_render_help() {
  std::cout
      << "usage: sylva render INPUT -o IMAGE [--backend auto|gl|cpu] [--width W --height H]\n"
         "                    [--aov depth,normal,uv,id] [--spp N] [--verbose]\n"
         "                    [-n STEPS] [--seed S] [-D NAME=VALUE]... [--max-modules N]\n\n"
         "Renders INPUT — a .scene.json scene, a .lsys grammar, a .skel.json skeleton or a .glb/.gltf\n"
         "written by `sylva export` (its skeletons are read back from node extras) (all but\n"
         "the scene in a default scene: the plant at the origin, the sun from (0.5, 1, 0.3), a\n"
         "camera framing it) — to IMAGE, written atomically. The format follows IMAGE's\n"
         "extension: .png (8-bit sRGB), .exr (linear half, AOVs as extra channels), or any\n"
         "format OpenImageIO writes. For a non-EXR IMAGE each AOV goes to its own EXR next to\n"
         "it: IMAGE without its extension + .depth.exr, .normal.exr, .uv.exr, .id.exr.\n\n"
         "  -o, --output IMAGE     the image to write\n"
         "      --backend B        auto (default: OpenGL, falling back to the CPU), gl, cpu;\n"
         "                         only the CPU ray caster exists in this version\n"
         "      --width W          image width in pixels (default: the scene's, else 1024)\n"
         "      --height H         image height in pixels (default: the scene's, else 768)\n"
         "      --aov LIST         extra outputs, comma-separated: depth (channel Z, distance\n"
         "                         from the eye, +inf on a miss), normal (N.X N.Y N.Z),\n"
         "                         uv (U V), id (id.plant id.chain id.segment)\n"
         "      --spp N            samples per pixel, stratified (default 1: pixel centres)\n"
         "      --verbose          list the passes that ran and what each cost\n"
         "grammar input only:\n"
         "  -n, --steps N          derivation steps (overrides 'derivation length:')\n"
         "      --seed S           random seed, an integer from 0 to 2^64-1\n"
         "  -D NAME=VALUE          override '#define NAME' (repeatable)\n"
         "      --max-modules N    stop with an error if a word would exceed N modules\n"
         "  -h, --help             show this help\n\n"
         "Exit status: 0 success, 1 bad input or unwritable output, 2 usage error,\n"
         "3 internal error, 130 interrupted (Ctrl-C; nothing is written).\n";
}

struct RenderArgs {
  GrammarArgs grammar;  // INPUT in .grammar, -o in .output
  std::string backend = "auto";
  std::optional<uint32_t> width, height;
  uint32_t aovs = 0;
  uint32_t spp = 1;
  bool verbose = false;
  bool grammar_flags = false;  // -n, --seed, -D or --max-modules given
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

uint32_t parse_size(const std::string& flag, const std::string& v, uint32_t max) {
  auto n = parse_u64(v);
  if (!n || *n == 0 || *n > max)
    throw UsageError{flag + " " + v + ": expected an integer from 1 to " + std::to_string(max)};
  return static_cast<uint32_t>(*n);
}

RenderArgs parse_render_args(const std::vector<std::string>& args) {
  RenderArgs out;
  std::vector<std::string> rest;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string a = args[i], inline_value;
    bool has_inline = false;
    if (a.rfind("--", 0) == 0 && a.find('=') != std::string::npos) {
      inline_value = a.substr(a.find('=') + 1);
      a = a.substr(0, a.find('='));
      has_inline = true;
    }
    auto value = [&]() -> std::string {
      if (has_inline) return inline_value;
      if (i + 1 >= args.size()) throw UsageError{a + " needs a value"};
      return args[++i];
    };
    if (a == "--backend") {
      out.backend = value();
      if (out.backend != "auto" && out.backend != "gl" && out.backend != "cpu")
        throw UsageError{"--backend " + out.backend + ": expected auto, gl or cpu"};
    } else if (a == "--width") {
      out.width = parse_size(a, value(), 65536);
    } else if (a == "--height") {
      out.height = parse_size(a, value(), 65536);
    } else if (a == "--spp") {
      out.spp = parse_size(a, value(), 65536);
    } else if (a == "--aov") {
      std::string list = value();
      size_t start = 0;
      for (;;) {
        size_t comma = list.find(',', start);
        std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        if (name == "depth") out.aovs |= kAovDepth;
        else if (name == "normal") out.aovs |= kAovNormal;
        else if (name == "uv") out.aovs |= kAovUv;
        else if (name == "id") out.aovs |= kAovId;
        else throw UsageError{"--aov: unknown AOV '" + name + "' (expected depth, normal, uv or id)"};
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
    } else if (a == "--verbose" || a == "-v") {
      out.verbose = true;
    } else {
      if (a == "-n" || a == "--steps" || a == "--seed" || a == "-D" || a == "--define" ||
          a == "--max-modules" || (a.size() > 2 && (a.rfind("-D", 0) == 0 || a.rfind("-n", 0) == 0)))
        out.grammar_flags = true;
      rest.push_back(args[i]);
    }
  }
  try {
    out.grammar = parse_grammar_args(rest, true);
  } catch (const UsageError& e) {
    if (e.message.rfind("missing GRAMMAR", 0) == 0)
      throw UsageError{"missing INPUT (a .lsys grammar, .skel.json skeleton or .scene.json scene)"};
    if (e.message.rfind("missing -o", 0) == 0) throw UsageError{"missing -o IMAGE"};
    if (e.message.rfind("unexpected argument", 0) == 0)
      throw UsageError{e.message.substr(0, e.message.find(" (one GRAMMAR")) + " (one INPUT only)"};
    throw;
  }
  return out;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Restores the previous SIGINT disposition when the render is over.
class SigintGuard {
 public:
  SigintGuard() {
    struct sigaction action {};
    action.sa_handler = on_sigint;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &previous_);
  }
  ~SigintGuard() { sigaction(SIGINT, &previous_, nullptr); }
  SigintGuard(const SigintGuard&) = delete;
  SigintGuard& operator=(const SigintGuard&) = delete;

 private:
  struct sigaction previous_ {};
};

}  // namespace

int run_render(const std::vector<std::string>& args) {
  RenderArgs a = parse_render_args(args);
  if (a.grammar.help) {
    print_render_help();
    return kOk;
  }
  const std::string& input = a.grammar.grammar;
  const std::string& output = a.grammar.output;
  const bool is_scene = ends_with(input, ".scene.json"), is_skeleton = ends_with(input, ".skel.json"),
             is_grammar = ends_with(input, ".lsys"), is_gltf = ends_with(input, ".glb") || ends_with(input, ".gltf");
  if (!is_scene && !is_skeleton && !is_grammar && !is_gltf)
    throw UsageError{"INPUT '" + input + "' must end in .lsys, .skel.json, .scene.json, .glb or .gltf"};
  if (a.grammar_flags && !is_grammar)
    throw UsageError{"-n, --seed, -D and --max-modules apply to a .lsys grammar only"};
  if (a.backend == "gl")
    throw UsageError{"--backend gl: the OpenGL backend is not available yet (use --backend cpu or auto)"};
  if (a.backend == "auto") std::cerr << "sylva render: OpenGL backend not available yet; using the CPU ray caster\n";
  if (!can_write_image_format(output))
    throw UsageError{"-o " + output + ": OpenImageIO cannot write this format (use .png, .exr, ...)"};

  SigintGuard sigint;
  g_interrupted.store(false);
  std::vector<RenderPass> passes;
  auto start = std::chrono::steady_clock::now();
  Scene scene;
  if (is_scene) {
    SceneReadResult read = read_scene_file(input);
    if (read.error) {
      std::cerr << read.error->format() << "\n";
      return kInputError;
    }
    scene = std::move(*read.scene);
    passes.push_back({"read scene", seconds_since(start), ""});
    start = std::chrono::steady_clock::now();
    if (auto error = grow_scene_plants(scene, a.grammar.max_modules)) {
      std::cerr << *error;
      if (!error->empty() && error->back() != '\n') std::cerr << "\n";
      return kInputError;
    }
    passes.push_back({"grow", seconds_since(start), std::to_string(scene.plants.size()) + " plants"});
  } else if (is_gltf) {
    // A file written by `sylva export`: its skeletons come back exactly from node extras.
    GltfImportResult imported = import_gltf_skeletons(input);
    if (imported.error) {
      std::cerr << *imported.error << "\n";
      return kInputError;
    }
    const uint32_t width = a.width.value_or(1024), height = a.height.value_or(768);
    scene = default_scene_for(imported.plants.front().skeleton, width, height);
    scene.plants.clear();
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    double lowest = 0;
    for (GltfPlant& p : imported.plants) {
      ScenePlant plant;
      plant.skeleton = std::move(p.skeleton);
      plant.position = {p.position_m[0], p.position_m[1], p.position_m[2]};
      plant.rotate_y_deg = p.rotate_y_deg;
      plant.scale = p.scale;
      const Skeleton placed = place_plant(plant);
      const SkeletonBounds b = skeleton_bounds(placed);
      lo = glm::min(lo, b.lo);
      hi = glm::max(hi, b.hi);
      for (const Joint& j : placed.joints) lowest = std::min(lowest, j.position_m[1]);
      scene.plants.push_back(std::move(plant));
    }
    scene.ground.height = lowest;
    scene.camera = framing_camera(lo, hi, width, height);
    passes.push_back({"read glTF", seconds_since(start), std::to_string(scene.plants.size()) + " plants"});
  } else {
    Skeleton skeleton;
    if (is_skeleton) {
      SkeletonReadResult read = read_skeleton_file(input);
      if (read.error) {
        std::cerr << read.error->format() << "\n";
        return kInputError;
      }
      skeleton = std::move(*read.skeleton);
      passes.push_back({"read skeleton", seconds_since(start), ""});
    } else {
      lsys::ParseOptions po;
      po.define_overrides = a.grammar.defines;
      auto g = lsys::load_grammar(input, po);
      if (!g) {
        const lsys::Diagnostic& d = g.error();
        if (d.loc.line == 0 && d.message.rfind("-D ", 0) == 0) {
          std::cerr << "sylva render: error: " << d.message << "\n";
          return kUsageError;
        }
        std::cerr << d.format();
        return kInputError;
      }
      lsys::DeriveOptions o;
      o.steps = a.grammar.steps;
      o.seed = a.grammar.seed;
      o.max_modules = a.grammar.max_modules;
      auto grown = grow(*g, o, input, a.grammar.defines);
      if (!grown) {
        std::cerr << grown.error().format();
        return kInputError;
      }
      skeleton = std::move(grown->skeleton);
      passes.push_back({"grow", seconds_since(start), std::to_string(grown->modules) + " modules"});
    }
    scene = default_scene_for(skeleton, a.width.value_or(1024), a.height.value_or(768));
  }
  if (a.width) scene.width = *a.width;
  if (a.height) scene.height = *a.height;

  RenderOptions options;
  options.spp = a.spp;
  options.aovs = a.aovs;
  options.cancel = &g_interrupted;
  options.progress = ::isatty(STDERR_FILENO) == 1;
  RenderResult result = render_cpu(scene, options);
  if (result.cancelled || g_interrupted.load()) {
    std::cerr << "sylva render: interrupted; nothing written\n";
    return kInterrupted;
  }
  passes.insert(passes.end(), result.passes.begin(), result.passes.end());

  start = std::chrono::steady_clock::now();
  ImageWriteResult written = write_render(output, result.image);
  if (written.error) {
    std::cerr << written.error->format() << "\n";
    return kInputError;
  }
  std::string files;
  for (const std::string& f : written.written) files += (files.empty() ? "" : ", ") + f;
  passes.push_back({"write", seconds_since(start), files});

  if (a.verbose) {
    std::cerr << "sylva render: " << scene.width << "x" << scene.height << ", " << a.spp << " spp, CPU ray caster"
              << (scene.fog ? "; fog is parsed but not rendered in this version" : "") << "\n";
    for (const RenderPass& p : passes) {
      char line[256];
      std::snprintf(line, sizeof line, "  %-22s %9.3f ms", p.name.c_str(), p.seconds * 1e3);
      std::cerr << line << (p.detail.empty() ? "" : "  " + p.detail) << "\n";
    }
  }
  return kOk;
}

}  // namespace sylva::cli
