// cli_render.cpp — `sylva render` (docs/spec/cli.md, docs/spec/scene.md): a scene, grammar or skeleton to an
// image through the OpenGL ray caster (render_gl.h, on a headless EGL context) or the CPU
// ray caster (render_cpu.h), as --backend says.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>

#include "app/front/batch.h"
#include "app/front/camera_flags.h"
#include "app/cli/cli.h"
#include "app/front/progress_bar.h"
#include "app/front/render_input.h"
#include "app/front/video.h"
#include "core/scene/animate.h"
#include "core/scene/render_output.h"
#include "core/util/image_io.h"
#include "core/util/limits.h"
#include "core/gl/gl_context.h"
#include "core/gl/gl_program.h"
#include "core/scene/render_common.h"
#include "core/cpu/render_cpu.h"
#include "app/front/render.h"
#include "core/gl/render_gl.h"
#include "core/grow/grow.h"
#include "core/grow/growth_tween.h"
#include "core/scene/scene.h"
#include "core/util/clock.h"

namespace sylva::cli {

namespace {

constexpr uint32_t kMaxConeParam = 100000;  // --cone-params: any larger is a typo

// --backend auto's rule (docs/spec/cli.md): OpenGL on a GPU; where the only GL is a software
// rasteriser (llvmpipe, softpipe) the CPU ray caster, which is several times faster there.
// Why auto declines `context`, or none where it takes it.
std::optional<std::string> auto_declines(const std::string& backend, const GlContext& context) {
  if (backend != "auto" || !context.info().software) return std::nullopt;
  return "--backend auto: " + context.info().renderer +
         " is a software rasteriser, slower than the CPU ray caster; --backend gl forces it";
}

std::atomic<bool> g_interrupted{false};
extern "C" void on_sigint(int) { g_interrupted.store(true); }
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT handler needs a lock-free flag");

void print_render_help() {
  std::cout
      << "usage: sylva render INPUT -o IMAGE [--backend auto|gl|cpu] [--width W --height H]\n"
         "                    [--aov depth,normal,uv,id,fog] [--spp N] [--verbose]\n"
         "                    [--eye X,Y,Z] [--target X,Y,Z] [--fov DEG] [--sun X,Y,Z]\n"
         "                    [--geometry frusta|mesh] [--mesh-level M] [--skin smooth|paper]\n"
         "                    [--fog-mode MODE] [--fog-steps N] [--photons N] [--cone-params P]\n"
         "                    [-n STEPS] [--seed S] [-D NAME=VALUE]... [--max-modules N]\n"
         "                    [--frames all|A..B [--fps F] [--video VIDEO]]\n\n"
         "Renders INPUT — a .scene.json scene, a .lsys grammar, a .skel.json skeleton or a .glb/.gltf\n"
         "written by `sylva export` (its skeletons are read back from node extras) (all but\n"
         "the scene in a default scene: the plant at the origin, the sun from (0.5, 1, 0.3), a\n"
         "camera framing it) — to IMAGE, written atomically. The format follows IMAGE's\n"
         "extension: .png (8-bit sRGB), .exr (linear half, AOVs as extra channels), or any\n"
         "format OpenImageIO writes. For a non-EXR IMAGE each AOV goes to its own EXR next to\n"
         "it: IMAGE without its extension + .depth.exr, .normal.exr, .uv.exr, .id.exr, .fog.exr.\n\n"
         "  -o, --output IMAGE     the image to write\n"
         "      --backend B        auto (default): OpenGL on a GPU (a window-less EGL context);\n"
         "                         the CPU ray caster where the only GL is a software\n"
         "                         rasteriser (Mesa's llvmpipe: the CPU is several times\n"
         "                         faster; --verbose says so) or none opens (saying why);\n"
         "                         gl: OpenGL, llvmpipe included, or exit 1 saying why; cpu:\n"
         "                         the CPU reference (fog's refined and reference: CPU only)\n"
         "      --width W          image width in pixels (default: the scene's, else 1024)\n"
         "      --height H         image height in pixels (default: the scene's, else 768)\n"
         "      --aov LIST         extra outputs, comma-separated: depth (channel Z, distance\n"
         "                         from the eye, +inf on a miss), normal (N.X N.Y N.Z),\n"
         "                         uv (U V), id (id.plant id.chain id.segment), fog (a scene\n"
         "                         with fog: fog.R fog.G fog.B, the light the fog scatters\n"
         "                         toward the eye, and fog.T, the transmittance to what the\n"
         "                         pixel's centre sees: beauty = fog.T x surface + fog.RGB)\n"
         "      --spp N            samples per pixel, stratified (default 8, where needles and\n"
         "                         twigs stop breaking up: docs/benchmarks.md; 1: the pixel\n"
         "                         centres, about 5x faster, aliased)\n"
         "      --verbose          list the passes that ran and what each cost\n"
         "      --eye X,Y,Z        the camera's eye in metres (Y up), e.g. --eye 6,3,6\n"
         "      --target X,Y,Z     the point it looks at, in metres\n"
         "      --fov DEG          its full vertical field of view in degrees, in (0, 180)\n"
         "      --sun X,Y,Z        the direction toward the sun (need not be unit; Y up), e.g.\n"
         "                         --sun 1,0.3,0 for a low sun from +X; overrides a scene's\n"
         "                         sun.direction (default scene: 0.5,1,0.3)\n"
         "                         (each overrides a scene's camera key; for a grammar or\n"
         "                         skeleton the default camera frames the plant, fov 35)\n"
         "      --geometry G       what stands for the plants: frusta (default: the exact\n"
         "                         conical frusta) or mesh (the polygon baseline: the frusta\n"
         "                         tessellated, displaced by bark height maps where a scene\n"
         "                         gives them)\n"
         "      --mesh-level M     the mesh's subdivision level, 0 to 6: 16·4^M triangles per\n"
         "                         segment (default 2)\n"
         "      --skin S           how chains meet, for every plant (over the scene's and the\n"
         "                         plants' skin keys): smooth (collars, domes, rounded bends;\n"
         "                         the default) or paper (Bhagvat et al. 2009's mitred chains,\n"
         "                         plain capped laterals, flat ends)\n"
         "a scene with fog only (each overrides the scene's fog key of the same name):\n"
         "      --fog-mode MODE    how the light the fog scatters is computed: auto (default:\n"
         "                         refined on the CPU, fast with OpenGL), brute (ray marching,\n"
         "                         a shadow ray per sample), reference (converged: every\n"
         "                         shadow edge bisected, 16 sun-\n"
         "                         disc points); medium (shadow rays only inside the shadow\n"
         "                         cones), fast (no sunlight inside them, no shadow rays) and\n"
         "                         refined (their edges bisected to the exact shadow) trace sun\n"
         "                         photons into shadow cones first (Hougs and Day 2001); map\n"
         "                         walks each ray through sun-space depth maps of the plants\n"
         "                         (exact up to their texels, no shadow rays; docs/fog-map.md)\n"
         "      --fog-steps N      samples along each ray, 1 to " << kFogMaxSteps << " (default 64)\n"
         "      --fog-map-resolution N  map: texels a side of each sun map, a multiple of 32\n"
         "                         from 32 to 65536 (default 2048)\n"
         "      --fog-map-directions N  map: maps over the sun's disc, 1 to " << kFogMaxMapDirections << " (default 4)\n"
         "      --photons N        sun photons for the shadow cones, 1 to " << kFogMaxPhotons << "\n"
         "                         (default 1000000)\n"
         "      --cone-params P    the cones' clustering: p1,p2,p3,p4 (neighbours >= p3 + 1,\n"
         "                         sectors >= 2, vectors per ring >= 1, least vectors per cone\n"
         "                         >= 1; each at most " << kMaxConeParam << ") or auto (default)\n"
         "animation (docs/animation.md):\n"
         "      --frames A..B      render frames A to B (or one frame N, or all: the scene's\n"
         "                         animation duration) to -o, which must hold {frame} (its\n"
         "                         number with 4 digits: -o frames/f_{frame}.png); a scene\n"
         "                         moves its plants as its animation key says (frame k at k/fps\n"
         "                         seconds), a grammar grows: frame k is k derivation steps\n"
         "                         (all: 0 to its derivation length), seen by the last frame's\n"
         "                         camera; so does a scene without an animation key, every\n"
         "                         plant that grows from a grammar in lockstep, in the scene's\n"
         "                         light (all stops at the first frame that shows the grown\n"
         "                         plants). Each frame is written atomically as it finishes\n"
         "      --substeps K       a growth's frames from one derivation step to the next\n"
         "                         (1 to 100, default 1): frame k is step k/K, what grows\n"
         "                         between two steps growing out smoothly (docs/animation.md)\n"
         "      --fps F            frames per second of the video (and of a scene's time):\n"
         "                         default the scene's animation fps, 4 for a grammar\n"
         "      --video VIDEO      also encode the PNG frames into VIDEO (.mp4, .mkv, .webm,\n"
         "                         .mov or .gif) with ffmpeg, which must be installed\n"
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
  uint32_t spp = kDefaultRenderSpp;
  bool verbose = false;
  CameraFlags camera;  // --eye, --target, --fov
  GeometryOptions geometry;
  FogRenderOptions fog;        // --fog-mode, --fog-steps, --photons, --cone-params
  bool fog_flags = false;      // any of them given
  bool grammar_flags = false;  // -n, --seed, -D or --max-modules given
  std::optional<std::string> frames;  // --frames, as given
  std::optional<double> fps;          // --fps
  uint32_t substeps = 1;              // --substeps: frames from one derivation step to the next
  std::optional<std::string> video;   // --video
  std::optional<SkinStyle> skin;      // --skin: every plant's, over the scene's keys
  std::optional<glm::dvec3> sun;      // --sun: toward the sun, over the scene's sun.direction
};

// The scene as --skin and --sun ask (nothing without them).
void apply_scene_flags(const RenderArgs& a, Scene& scene) {
  if (a.skin) override_skin(scene, *a.skin);
  if (a.sun) scene.sun.direction = unit_sun_direction(*a.sun);
}

// --cone-params p1,p2,p3,p4 (Hougs and Day 2001 sec. 3.2.1) or auto (nullopt): four integers with
// p1 >= p3 + 1 (a ring needs its seed and p3 neighbours), p2 >= 2, p3 >= 1, p4 >= 1.
std::optional<std::array<uint32_t, 4>> parse_cone_params(const std::string& v) {
  if (v == "auto") return std::nullopt;
  const std::string expected = "--cone-params " + v +
                               ": expected auto or p1,p2,p3,p4: integers with p1 >= p3 + 1, p2 >= 2, p3 >= 1, "
                               "p4 >= 1, each at most " + std::to_string(kMaxConeParam);
  std::array<uint32_t, 4> p{};
  size_t start = 0;
  for (int k = 0; k < 4; ++k) {
    const size_t comma = v.find(',', start);
    if ((k < 3) != (comma != std::string::npos)) throw UsageError{expected};
    auto n = parse_u64(v.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (!n || *n > kMaxConeParam) throw UsageError{expected};
    p[k] = static_cast<uint32_t>(*n);
    start = comma + 1;
  }
  if (p[0] < p[2] + 1 || p[1] < 2 || p[2] < 1 || p[3] < 1) throw UsageError{expected};
  return p;
}

// An argument left for the grammar flags that is -n, --seed, -D or --max-modules, in any
// spelling ("-n5", "--seed=3"): those shape a grammar only.
bool is_derive_flag(const std::string& arg) {
  const std::string name = arg.starts_with("--") ? arg.substr(0, arg.find('=')) : arg;
  return name == "-n" || name == "--steps" || name == "--seed" || name == "-D" || name == "--define" ||
         name == "--max-modules" || (name.size() > 2 && (name.starts_with("-D") || name.starts_with("-n")));
}

RenderArgs parse_render_args(const std::vector<std::string>& args) {
  RenderArgs out;
  FlagTable table;
  table.inline_values = InlineValues::all_flags;
  table.leaves_others = true;  // INPUT, -o and the grammar flags: parse_grammar_args's
  table.flags = {
      value_flag({"--backend"},
                 [&out](const std::string&, const std::string& v) {
                   out.backend = v;
                   if (out.backend != "auto" && out.backend != "gl" && out.backend != "cpu")
                     throw UsageError{"--backend " + out.backend + ": expected auto, gl or cpu"};
                 }),
      skin_flag(out.skin),
      count_flag({"--width"}, out.width, 65536),
      count_flag({"--height"}, out.height, 65536),
      count_flag({"--spp"}, out.spp, 65536),
      value_flag({"--aov"},
                 [&out](const std::string&, const std::string& list) {
                   size_t start = 0;
                   for (;;) {
                     size_t comma = list.find(',', start);
                     std::string name =
                         list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
                     if (name == "depth") out.aovs |= kAovDepth;
                     else if (name == "normal") out.aovs |= kAovNormal;
                     else if (name == "uv") out.aovs |= kAovUv;
                     else if (name == "id") out.aovs |= kAovId;
                     else if (name == "fog") out.aovs |= kAovFog;
                     else throw UsageError{"--aov: unknown AOV '" + name + "' (expected depth, normal, uv, id or fog)"};
                     if (comma == std::string::npos) break;
                     start = comma + 1;
                   }
                 }),
      value_flag({"--geometry"},
                 [&out](const std::string&, const std::string& g) {
                   if (g == "frusta") out.geometry.kind = GeometryKind::frusta;
                   else if (g == "mesh") out.geometry.kind = GeometryKind::mesh;
                   else throw UsageError{"--geometry " + g + ": expected frusta or mesh"};
                 }),
      value_flag({"--mesh-level"},
                 [&out](const std::string&, const std::string& v) {
                   auto n = parse_u64(v);
                   if (!n || *n > 6) throw UsageError{"--mesh-level " + v + ": expected an integer from 0 to 6"};
                   out.geometry.mesh_level = static_cast<int>(*n);
                 }),
      noting_given(value_flag({"--fog-mode"},
                              [&out](const std::string&, const std::string& v) {
                                const std::optional<FogMode> mode = fog_mode_from_name(v);
                                if (!mode)
                                  throw UsageError{"--fog-mode " + v +
                                                   ": expected auto, brute, medium, fast, refined, reference or map"};
                                out.fog.mode = *mode;
                              }),
                   out.fog_flags),
      noting_given(count_flag({"--fog-steps"}, out.fog.steps, kFogMaxSteps), out.fog_flags),
      noting_given(value_flag({"--fog-map-resolution"},
                              [&out](const std::string&, const std::string& v) {
                                auto n = parse_u64(v);
                                if (!n || *n < kFogMinMapResolution || *n > kFogMaxMapResolution || *n % 32 != 0)
                                  throw UsageError{"--fog-map-resolution " + v + ": expected a multiple of 32 from " +
                                                   std::to_string(kFogMinMapResolution) + " to " +
                                                   std::to_string(kFogMaxMapResolution)};
                                out.fog.map_resolution = static_cast<uint32_t>(*n);
                              }),
                   out.fog_flags),
      noting_given(count_flag({"--fog-map-directions"}, out.fog.map_directions, kFogMaxMapDirections), out.fog_flags),
      noting_given(value_flag({"--photons"},
                              [&out](const std::string&, const std::string& v) {
                                auto n = parse_u64(v);
                                if (!n || *n == 0 || *n > kFogMaxPhotons)
                                  throw UsageError{"--photons " + v + ": expected an integer from 1 to " +
                                                   std::to_string(kFogMaxPhotons)};
                                out.fog.photons = *n;
                              }),
                   out.fog_flags),
      noting_given(value_flag({"--cone-params"},
                              [&out](const std::string&, const std::string& v) {
                                out.fog.cone_params = parse_cone_params(v);
                              }),
                   out.fog_flags),
      value_flag({"--frames"}, [&out](const std::string&, const std::string& v) { out.frames = v; }),
      value_flag({"--fps"},
                 [&out](const std::string&, const std::string& v) {
                   char* end = nullptr;
                   const double fps = std::strtod(v.c_str(), &end);
                   if (v.empty() || *end != '\0' || !(fps > 0 && fps <= 1000))
                     throw UsageError{"--fps " + v + ": expected a number of frames per second in (0, 1000]"};
                   out.fps = fps;
                 }),
      value_flag({"--substeps"},
                 [&out](const std::string&, const std::string& v) {
                   char* end = nullptr;
                   const long k = std::strtol(v.c_str(), &end, 10);
                   if (v.empty() || *end != '\0' || k < 1 || k > 100)
                     throw UsageError{"--substeps " + v + ": expected an integer from 1 to 100"};
                   out.substeps = static_cast<uint32_t>(k);
                 }),
      value_flag({"--video"}, [&out](const std::string&, const std::string& v) { out.video = v; }),
      value_flag({"--eye"},
                 [&out](const std::string& spelled, const std::string& v) {
                   out.camera.eye = parse_point_flag(spelled, v);
                 }),
      value_flag({"--target"},
                 [&out](const std::string& spelled, const std::string& v) {
                   out.camera.target = parse_point_flag(spelled, v);
                 }),
      value_flag({"--sun"},
                 [&out](const std::string& spelled, const std::string& v) {
                   const glm::dvec3 d = parse_point_flag(spelled, v);
                   if (d == glm::dvec3(0)) throw UsageError{spelled + " " + v + ": the direction toward the sun must not be zero"};
                   out.sun = d;
                 }),
      value_flag({"--fov"},
                 [&out](const std::string&, const std::string& v) { out.camera.fov_y_deg = parse_fov_flag(v); }),
      set_flag({"--verbose", "-v"}, out.verbose),
  };
  const std::vector<std::string> rest = parse_flags(args, table);
  out.grammar_flags = std::ranges::any_of(rest, is_derive_flag);
  out.grammar = parse_grammar_args(
      rest, {.wants_output = true,
             .missing_input = "missing INPUT (a .lsys grammar, .skel.json skeleton or .scene.json scene)",
             .missing_output = "missing -o IMAGE",
             .input_name = "INPUT"});
  return out;
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

// --frames: all, one frame N, or A..B.
struct FrameRange {
  uint64_t first = 0, last = 0;
  bool all = false;  // the animation's duration, or 0 .. the grammar's derivation length
  uint64_t count() const { return last - first + 1; }
};

constexpr uint64_t kMaxFrameNumber = 1'000'000'000;

FrameRange parse_frames(const std::string& v) {
  if (v == "all") return {0, 0, true};
  const size_t dots = v.find("..");
  const auto first = parse_u64(v.substr(0, dots));
  const auto last = dots == std::string::npos ? first : parse_u64(v.substr(dots + 2));
  if (!first || !last || *last > kMaxFrameNumber)
    throw UsageError{"--frames " + v + ": expected all, a frame N or a range A..B of integers from 0 to " +
                     std::to_string(kMaxFrameNumber)};
  if (*first > *last) throw UsageError{"--frames " + v + ": the range is empty (the first frame is after the last)"};
  if (*last - *first >= kMaxAnimationFrames)
    throw UsageError{"--frames " + v + ": at most " + std::to_string(kMaxAnimationFrames) + " frames in one command"};
  return {*first, *last, false};
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, s < 10 ? "%.2f s" : "%.0f s", s);
  return buf;
}

// `sylva render INPUT --frames ...` (docs/animation.md): one image per frame, each written
// atomically as it finishes. A scene's plants move (sway_scene_plants at frame / fps); on
// the GL backend the renderer is made once and every later frame re-skins and re-uploads
// only the segment records (GlRenderer::update_plants) — with fog, whose photons and cones
// depend on where the plants are, every frame is rendered whole. A grammar grows: frame k
// is k derivation steps, each a new renderer sharing the context's programs; so does a
// scene without an animation key whose plants grow from grammars (all in lockstep, in its
// light): frame k is every plant grown min(k, its derivation length) steps.
int run_render_frames(const RenderArgs& a) {
  const std::string& input = a.grammar.grammar;
  const std::string& pattern = a.grammar.output;
  const bool grammar_growth = is_grammar_input(input);
  if (!grammar_growth && !input.ends_with(".scene.json"))
    throw UsageError{"--frames applies to a .scene.json scene (with an animation key its plants move; without one "
                     "they grow) or a .lsys grammar (frame k is k derivation steps)"};
  if (grammar_growth && a.grammar.steps) throw UsageError{"--frames on a grammar sets the derivation steps: leave out -n"};
  if (!has_frame_placeholder(pattern))
    throw UsageError{"-o " + pattern + ": with --frames the output must hold {frame}, e.g. -o frames/f_{frame}.png"};
  check_pattern_separates(pattern, "{frame}");
  FrameRange range = parse_frames(*a.frames);
  std::optional<std::string> ffmpeg;
  if (a.video) {
    if (!pattern.ends_with(".png")) throw UsageError{"--video encodes PNG frames: -o must end in .png"};
    if (!video_container_for(*a.video))
      throw UsageError{"--video " + *a.video + ": expected a .mp4, .mkv, .webm, .mov or .gif file"};
    ffmpeg = find_ffmpeg();
    if (!ffmpeg) {
      std::cerr << "sylva render: --video needs ffmpeg, which is not installed (Debian: apt-get install ffmpeg); "
                   "nothing rendered\n";
      return kInputError;
    }
    if (Status allowed = check_output_path(*a.video); !allowed) {
      std::cerr << allowed.error().format();
      return kInputError;
    }
  }

  SigintGuard sigint;
  g_interrupted.store(false);
  std::vector<RenderPass> passes;
  // The scene whose plants move, or the grammar's last frame (its camera and ground frame
  // every frame, so the plant grows in a still view).
  GrammarArgs last_args = a.grammar;
  const bool all_frames = range.all;  // growth stops at the first frame that is the last's
  if (grammar_growth) {
    int code = kOk;
    const std::optional<lsys::Grammar> g = load_grammar_for(a.grammar, &code);
    if (!g) return code;
    if (range.all) range = {0, static_cast<uint64_t>(std::max<int64_t>(0, g->steps)) * a.substeps, false};
    last_args.steps = static_cast<int64_t>((range.last + a.substeps - 1) / a.substeps);
  }
  auto loaded = load_render_input(last_args, a.width, a.height, passes, Progress(&g_interrupted));
  if (auto* code = std::get_if<ExitCode>(&loaded)) {
    if (*code == kInterrupted) std::cerr << "sylva render: interrupted while growing; nothing written\n";
    return *code;
  }
  Scene base = std::move(std::get<Scene>(loaded));
  if (auto warning = empty_plants_warning(base, a.grammar.grammar)) std::cerr << *warning << "\n";
  apply_scene_flags(a, base);
  apply_camera_flags(a.camera, base.camera);
  // A scene without an animation key grows, when any of its plants grows from a grammar.
  const int64_t scene_length = grammar_growth || base.animation ? 0 : scene_growth_length(base);
  const bool scene_growth = !grammar_growth && !base.animation &&
                            std::ranges::any_of(base.plants, [](const ScenePlant& p) { return !p.grammar.empty(); });
  const bool growth = grammar_growth || scene_growth;
  if (!growth && !base.animation)
    throw UsageError{"--frames: " + input + " has no animation key and no plant that grows from a grammar: "
                     "nothing moves or grows (docs/animation.md)"};
  if (!growth && a.substeps != 1)
    throw UsageError{"--substeps applies to a growth (a grammar, or a scene without an animation key)"};
  if (scene_growth && range.all) range = {0, static_cast<uint64_t>(scene_length) * a.substeps, false};
  if (range.count() > kMaxAnimationFrames)
    throw UsageError{"--substeps " + std::to_string(a.substeps) + ": " + std::to_string(range.count()) +
                     " frames, more than the limit of " + std::to_string(kMaxAnimationFrames) + " in one command"};
  // --fps is a scene's time step too (docs/animation.md): frame k at k / fps seconds, and
  // `all` the frames of its duration at that rate.
  if (!growth && a.fps) {
    if (!(base.animation->duration_s * *a.fps <= static_cast<double>(kMaxAnimationFrames)))
    {
      char text[160];
      std::snprintf(text, sizeof text, "--fps %g: %g frames a second over the scene's %g s ask for more than %llu frames",
                    *a.fps, *a.fps, base.animation->duration_s, static_cast<unsigned long long>(kMaxAnimationFrames));
      throw UsageError{text};
    }
    base.animation->fps = *a.fps;
  }
  if (range.all) range = {0, animation_frame_count(*base.animation) - 1, false};
  const double fps = a.fps.value_or(growth ? 4.0 : base.animation->fps);
  if (auto problem = image_size_problem(base.width, base.height, a.spp)) {
    std::cerr << "sylva render: error: " << *problem << "\n";
    return kInputError;
  }
  if (auto problem = image_format_size_problem(pattern, base.width, base.height)) {
    std::cerr << file_diagnostic(pattern, *problem).format();
    return kInputError;
  }
  if (!base.fog && (a.fog_flags || (a.aovs & kAovFog)))
    throw UsageError{"--fog-mode, --fog-steps, --fog-map-resolution, --fog-map-directions, --photons, --cone-params and --aov fog apply to a scene with fog "
                     "only ('" + input + "' has no fog key)"};
  // Every frame's outputs are checked before the first is rendered.
  for (uint64_t f = range.first; f <= range.last; ++f)
    for (const std::string& target : render_output_paths(expand_frame_pattern(pattern, f), a.aovs))
      if (Status allowed = check_output_path(target); !allowed) {
        std::cerr << allowed.error().format();
        return kInputError;
      }

  RenderOptions options;
  options.spp = a.spp;
  options.aovs = a.aovs;
  options.geometry = a.geometry;
  options.fog = a.fog;
  options.progress = Progress(&g_interrupted);
  // The backend, chosen once for every frame as a single render chooses it.
  std::unique_ptr<GlContext> context;
  std::string backend_note;  // why auto took the CPU where a GL context opened
  if (a.backend != "cpu") {
    std::string why_not;
    if (auto unsupported = gl_unsupported(base, options)) {
      why_not = *unsupported;
    } else {
      GlContextResult made = create_headless_gl_context();
      if (made.context) context = std::move(made.context);
      else why_not = made.error;
    }
    if (context) {
      if (auto declined = auto_declines(a.backend, *context)) {
        context.reset();
        backend_note = " (" + *declined + ")";
      }
    } else {
      if (a.backend == "gl") {
        std::cerr << "sylva render: --backend gl: " << why_not << "\n";
        return kInputError;
      }
      std::cerr << "sylva render: OpenGL unavailable (" << why_not << "); using the CPU ray caster\n";
    }
  }
  std::cerr << "sylva render: " << range.count() << (range.count() == 1 ? " frame" : " frames") << " (" << range.first
            << ".." << range.last << ") of " << base.width << "x" << base.height << ", "
            << (context ? "OpenGL ray caster (" + context->info().renderer + ")" : "CPU ray caster" + backend_note)
            << "\n";

  std::vector<Skeleton> rest;
  for (const ScenePlant& p : base.plants) rest.push_back(*p.skeleton);
  // `--frames all` of a growth: the frames after the first whose plants have the last
  // frame's shapes would repeat its picture (a plant that has stopped growing), so they
  // are left out (docs/animation.md).
  auto grown_out = [&](const Scene& scene) {
    if (!growth || !all_frames || scene.plants.size() != rest.size()) return false;
    for (size_t i = 0; i < rest.size(); ++i) {
      const Skeleton& s = *scene.plants[i].skeleton;
      if (s.joints != rest[i].joints || s.chains != rest[i].chains || s.leaves != rest[i].leaves) return false;
    }
    return true;
  };
  std::optional<uint64_t> stopped_at;
  // A growth's scenes by step, the last two kept: the frames between two steps need both.
  std::map<uint64_t, Scene> grown;
  auto grown_to = [&](uint64_t step, std::optional<ExitCode>& failed) -> const Scene* {
    if (auto found = grown.find(step); found != grown.end()) return &found->second;
    GrammarArgs args = a.grammar;
    if (grammar_growth) args.steps = static_cast<int64_t>(step);
    std::vector<RenderPass> ignored;
    auto loaded = load_render_input(args, a.width, a.height, ignored, Progress(&g_interrupted),
                                    scene_growth ? std::optional<int64_t>(static_cast<int64_t>(step)) : std::nullopt);
    if (auto* code = std::get_if<ExitCode>(&loaded)) {
      failed = *code;
      return nullptr;
    }
    while (grown.size() >= 2) grown.erase(grown.begin());
    return &grown.emplace(step, std::move(std::get<Scene>(loaded))).first->second;
  };
  const SwayParameters sway = base.animation ? sway_parameters_of(*base.animation) : SwayParameters{};
  auto programs = std::make_shared<GlProgramCache>();
  std::unique_ptr<GlRenderer> renderer;  // the moving scene's, made at its first frame
  double update_s = 0, uploaded_bytes = 0;
  uint64_t updates = 0, done = 0;
  const auto start = std::chrono::steady_clock::now();
  for (uint64_t f = range.first; f <= range.last; ++f) {
    if (g_interrupted.load()) break;
    const auto frame_start = std::chrono::steady_clock::now();
    Scene scene = base;
    const uint64_t step_below = f / a.substeps;
    const double alpha = static_cast<double>(f % a.substeps) / a.substeps;  // 0: a whole step
    if (growth) {
      std::optional<ExitCode> failed;
      const Scene* before = grown_to(step_below, failed);
      const Scene* after = before && alpha > 0 ? grown_to(step_below + 1, failed) : before;
      if (failed) {
        if (*failed == kInterrupted) break;  // said below, with the frames kept
        return *failed;
      }
      scene = *after;
      if (alpha > 0)  // between two steps: what grows grows out (growth_tween.h)
        for (size_t i = 0; i < scene.plants.size() && i < before->plants.size(); ++i)
          scene.plants[i].skeleton = tween_growth(*before->plants[i].skeleton, *after->plants[i].skeleton, alpha);
      apply_scene_flags(a, scene);
      scene.camera = base.camera;
      scene.ground = base.ground;
    } else {
      sway_scene_plants(scene, rest, animation_frame_time_s(*base.animation, f), sway);
    }
    bool any_segment = false;
    for (const ScenePlant& p : scene.plants) any_segment |= p.skeleton->segment_count() > 0;
    RenderResult result;
    try {
    if (!context || !any_segment) {
      // The CPU draws a frame without segments too (a grammar's axiom: sky and ground).
      result = render_cpu(scene, options);
    } else {
      context->make_current();
      if (scene.fog) {
        result = render_gl_scene(scene, options);
      } else if (growth || !renderer) {
        renderer = std::make_unique<GlRenderer>(scene, options, programs);
        result = renderer->render(scene);
      } else {
        const auto t0 = std::chrono::steady_clock::now();
        uploaded_bytes += static_cast<double>(renderer->update_plants(scene));
        update_s += seconds_since(t0);
        ++updates;
        result = renderer->render(scene);
      }
    }
    } catch (const GlCancelled&) {
      break;  // Ctrl-C while the plants were skinned
    }
    if (result.cancelled || g_interrupted.load()) break;
    Expected<std::string> path = frame_output_path(pattern, f);
    if (!path) {
      std::cerr << path.error().format();
      return kInputError;
    }
    Expected<std::vector<std::string>> written = write_render(*path, result.image);
    if (!written) {
      std::cerr << written.error().format();
      return kInputError;
    }
    ++done;
    const double elapsed = seconds_since(start);
    const double left = elapsed / static_cast<double>(done) * static_cast<double>(range.count() - done);
    std::cerr << "sylva render: [" << done << "/" << range.count() << "] frame " << f << ": " << *path << " ("
              << seconds_text(seconds_since(frame_start))
              << (done < range.count() ? "; about " + seconds_text(left) + " left)" : ")") << "\n";
    if (f < range.last && alpha == 0 && grown_out(scene)) {
      stopped_at = f;
      std::cerr << "sylva render: frame " << f << " already shows the grown plants: frames " << f + 1 << ".."
                << range.last << " would repeat it and are left out\n";
      break;
    }
  }
  if (stopped_at) range.last = *stopped_at;  // what was asked for is written
  if (done < range.count()) {
    std::cerr << "sylva render: interrupted after " << done << " of " << range.count()
              << " frames (the frames written stay; the frame in progress was not written"
              << (a.video ? "; no video" : "") << ")\n";
    return kInterrupted;
  }
  std::cerr << "sylva render: " << done << (done == 1 ? " frame" : " frames") << " in "
            << seconds_text(seconds_since(start)) << " (" << seconds_text(seconds_since(start) / static_cast<double>(done))
            << " a frame)";
  if (updates > 0) {
    char line[160];
    std::snprintf(line, sizeof line, "; re-skin + upload %.2f ms and %.0f KiB a frame", update_s * 1e3 / updates,
                  uploaded_bytes / 1024 / updates);
    std::cerr << line;
  }
  std::cerr << "\n";
  if (a.video) {
    if (Status encoded = encode_video(*ffmpeg, pattern, range.first, range.count(), fps, *a.video, &g_interrupted);
        !encoded) {
      std::cerr << encoded.error().format();
      return g_interrupted.load() ? kInterrupted : kInputError;
    }
    std::cerr << "sylva render: wrote " << *a.video << " (" << done << " frames at " << fps << " fps)\n";
  }
  return kOk;
}

}  // namespace

int run_render(const std::vector<std::string>& args) {
  RenderArgs a = parse_render_args(args);
  if (a.grammar.help) {
    print_render_help();
    return kOk;
  }
  const std::string& input = a.grammar.grammar;
  const std::string& output = a.grammar.output;
  if (!is_render_input(input))
    throw UsageError{"INPUT '" + input + "' must be a grammar (.lsys, a cpfg .l or a vlab object), .skel.json, .scene.json, .glb or .gltf"};
  if (a.grammar_flags && !is_grammar_input(input))
    throw UsageError{"-n, --seed, -D and --max-modules apply to a grammar only"};
  if (!can_write_image_format(output))
    throw UsageError{"-o " + output + ": OpenImageIO cannot write this format (use .png, .exr, ...)"};
  if (a.frames) return run_render_frames(a);
  if (a.fps || a.video) throw UsageError{"--fps and --video apply with --frames only"};
  if (has_frame_placeholder(output))
    throw UsageError{"-o " + output + " holds {frame}: give --frames A..B to render frames"};

  SigintGuard sigint;
  g_interrupted.store(false);
  std::vector<RenderPass> passes;
  auto loaded = load_render_input(a.grammar, a.width, a.height, passes, Progress(&g_interrupted));
  if (auto* code = std::get_if<ExitCode>(&loaded)) {
    if (*code == kInterrupted) std::cerr << "sylva render: interrupted while growing; nothing written\n";
    return *code;
  }
  Scene scene = std::move(std::get<Scene>(loaded));
  if (auto warning = empty_plants_warning(scene, a.grammar.grammar)) std::cerr << *warning << "\n";
  apply_scene_flags(a, scene);
  apply_camera_flags(a.camera, scene.camera);
  if (auto problem = image_size_problem(scene.width, scene.height, a.spp)) {
    std::cerr << "sylva render: error: " << *problem << "\n";
    return kInputError;
  }
  if (auto problem = image_format_size_problem(output, scene.width, scene.height)) {
    std::cerr << file_diagnostic(output, *problem).format();
    return kInputError;
  }
  // Every output is checked now, with the inputs read, rather than after the render.
  for (const std::string& target : render_output_paths(output, a.aovs))
    if (Status allowed = check_output_path(target); !allowed) {
      std::cerr << allowed.error().format();
      return kInputError;
    }
  auto start = std::chrono::steady_clock::now();
  if (!scene.fog && (a.fog_flags || (a.aovs & kAovFog)))
    throw UsageError{"--fog-mode, --fog-steps, --fog-map-resolution, --fog-map-directions, --photons, --cone-params and --aov fog apply to a scene with fog "
                     "only ('" + input + "' has no fog key)"};

  RenderOptions options;
  options.spp = a.spp;
  options.aovs = a.aovs;
  options.geometry = a.geometry;
  options.fog = a.fog;
  ProgressBar bar("sylva render", ::isatty(STDERR_FILENO) == 1);
  options.progress = bar.progress(&g_interrupted);
  // The backend (docs/spec/cli.md): gl, or for auto OpenGL where a context can be made and the scene
  // needs nothing the GL backend lacks; otherwise the CPU, saying why.
  std::string backend_name = "CPU ray caster";
  std::optional<RenderResult> gl_result;
  GlFrameStats gl_stats;
  bool software_gl = false;  // auto found only a software rasteriser: the CPU, by choice
  if (a.backend != "cpu") {
    std::string why_not;
    const char* fallback = "OpenGL unavailable";
    if (auto unsupported = gl_unsupported(scene, options)) {
      why_not = *unsupported;
      fallback = "the OpenGL backend cannot draw this";
    } else {
      const auto context_start = std::chrono::steady_clock::now();
      GlContextResult context = create_headless_gl_context();
      if (!context.context) {
        why_not = context.error;
      } else if (auto declined = auto_declines(a.backend, *context.context)) {
        // The CPU, quietly; --verbose says why.
        backend_name = "CPU ray caster (" + *declined + ")";
        passes.push_back({"gl context", seconds_since(context_start),
                          context.context->info().describe() + ": not used"});
        software_gl = true;
      } else {
        passes.push_back({"gl context", seconds_since(context_start), context.context->info().describe()});
        try {
          gl_result = render_gl_scene(scene, options, &gl_stats);
          // Meshes are rasterised (the polygon baseline), frusta ray cast.
          const std::string& renderer = context.context->info().renderer;
          backend_name = options.geometry.kind == GeometryKind::mesh ? "OpenGL rasteriser (meshes, " + renderer + ")"
                                                                     : "OpenGL ray caster (" + renderer + ")";
          // auto names what it chose (the fallback below names the CPU and why).
          if (a.backend == "auto") std::cerr << "sylva render: --backend auto: " << backend_name << "\n";
        } catch (const GlError& e) {
          why_not = e.what();
        }
      }
    }
    if (!gl_result && !software_gl) {
      if (a.backend == "gl") {
        std::cerr << "sylva render: --backend gl: " << why_not << "\n";
        return kInputError;
      }
      std::cerr << "sylva render: " << fallback << " (" << why_not << "); using the CPU ray caster\n";
    }
  }
  RenderResult result = gl_result ? std::move(*gl_result) : render_cpu(scene, options);
  bar.finish();
  if (result.cancelled || g_interrupted.load()) {
    std::cerr << "sylva render: interrupted; nothing written\n";
    return kInterrupted;
  }
  passes.insert(passes.end(), result.passes.begin(), result.passes.end());

  start = std::chrono::steady_clock::now();
  Expected<std::vector<std::string>> written = write_render(output, result.image);
  if (!written) {
    std::cerr << written.error().format();
    return kInputError;
  }
  std::string files;
  for (const std::string& f : *written) files += (files.empty() ? "" : ", ") + f;
  passes.push_back({"write", seconds_since(start), files});

  if (a.verbose) {
    std::cerr << "sylva render: " << scene.width << "x" << scene.height << ", " << a.spp << " spp, " << backend_name
              << "\n";
    auto print = [](const char* name, double seconds, const std::string& detail) {
      char line[256];
      std::snprintf(line, sizeof line, "  %-22s %9.3f ms", name, seconds * 1e3);
      std::cerr << line << (detail.empty() ? "" : "  " + detail) << "\n";
    };
    for (const RenderPass& p : passes) print(p.name.c_str(), p.seconds, p.detail);
    if (!result.cone_report.empty()) std::cerr << result.cone_report;
    if (gl_result) {
      // The GL frame's totals (GlFrameStats): GPU time over its passes, what it sent, what it holds.
      print("GPU total", gl_stats.gpu_s(),
            std::to_string((gl_stats.plant_bytes_uploaded + 1023) / 1024) + " KiB of plant data uploaded, " +
                std::to_string((gl_stats.target_bytes + 1023) / 1024) + " KiB of render targets");
    }
  }
  return kOk;
}

}  // namespace sylva::cli
