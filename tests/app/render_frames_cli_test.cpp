// render_frames_cli_test.cpp — `sylva render --frames` (docs/animation.md): a scene's
// animation key moving its plants frame by frame, a grammar (or a scene without an
// animation key) growing over its derivation steps, the per-frame outputs, the video through ffmpeg, and the usage errors.
// Every render here passes --spp 1 (the pixel centres): these tests are about what is
// drawn, not how it is sampled, and the default of 8 samples would cost 8 times the time
// (RenderCli.TheDefaultIsEightSamplesPerPixel pins the default).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

namespace fs = std::filesystem;

const std::string kCactus = std::string(SYLVA_SOURCE_DIR) + "/presets/cactus.lsys";
const std::string kElm = std::string(SYLVA_SOURCE_DIR) + "/presets/elm.lsys";

// Two cacti, seen closely so that their sway moves many pixels; `animation`: the key's
// value, empty for none.
std::string write_scene(TempDir& dir, const std::string& animation) {
  fs::copy_file(kCactus, dir.file("cactus.lsys"), fs::copy_options::overwrite_existing);
  dir.write("c.scene.json", R"({"image": {"width": 64, "height": 48},
  "camera": {"eye": [2.5, 1.2, 3.5], "target": [0, 0.8, 0]},
  )" + (animation.empty() ? std::string() : "\"animation\": " + animation + ",") + R"(
  "plants": [{"grammar": "cactus.lsys", "seed": 3}, {"grammar": "cactus.lsys", "seed": 4, "position": [0.8, 0, -0.5]}]})");
  return dir.file("c.scene.json");
}

const char* const kDance = R"({"motion": "dance", "fps": 10, "duration_s": 0.4})";

std::vector<float> pixels(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> p(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, p.data())) return {};
  return p;
}

double mean_abs_difference(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size() || a.empty()) return INFINITY;
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += std::abs(a[i] - b[i]);
  return sum / static_cast<double>(a.size());
}

bool gl_missing(const ProcessResult& r) {
  return r.exit_code == 1 && r.err.find("--backend gl") != std::string::npos;
}

TEST(RenderFrames, ASceneWritesOneImagePerFrameAndItsPlantsMove) {
  TempDir dir;
  const std::string scene = write_scene(dir, kDance);
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "--frames", "all", "-o", dir.file("out/f_{frame}.png"), "--backend", "cpu"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  // all: ceil(0.4 s × 10 fps) = 4 frames, numbered with four digits, in a folder made for them.
  for (const char* f : {"f_0000.png", "f_0001.png", "f_0002.png", "f_0003.png"})
    EXPECT_TRUE(fs::exists(dir.file(std::string("out/") + f))) << f << "\n" << describe(r);
  EXPECT_FALSE(fs::exists(dir.file("out/f_0004.png")));
  EXPECT_NE(r.err.find("[4/4] frame 3"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("4 frames in"), std::string::npos) << describe(r);
  // Frame 0 is the rest pose (t = 0): the still scene's picture, pixel for pixel; later
  // frames are not.
  const std::string still = write_scene(dir, "");
  ProcessResult plain = run_sylva({"render", "--spp", "1", still, "-o", dir.file("still.png"), "--backend", "cpu"});
  ASSERT_EQ(plain.exit_code, 0) << describe(plain);
  const std::vector<float> rest = pixels(dir.file("still.png"));
  EXPECT_EQ(mean_abs_difference(pixels(dir.file("out/f_0000.png")), rest), 0.0);
  EXPECT_GT(mean_abs_difference(pixels(dir.file("out/f_0002.png")), rest), 1e-3);
}

TEST(RenderFrames, FpsIsTheScenesTimeStepToo) {
  // docs/animation.md: --fps sets the time step of a scene's frames (frame k at k / fps s)
  // and `all` covers the scene's duration at that rate.
  TempDir dir;
  const std::string scene = write_scene(dir, kDance);  // 10 fps, 0.4 s
  ProcessResult ten = run_sylva({"render", "--spp", "1", scene, "--frames", "1", "-o", dir.file("ten_{frame}.png"),
                                 "--backend", "cpu", "--width", "64", "--height", "48"});
  ASSERT_EQ(ten.exit_code, 0) << describe(ten);
  ProcessResult twenty = run_sylva({"render", "--spp", "1", scene, "--frames", "all", "-o", dir.file("tw_{frame}.png"),
                                    "--fps", "20", "--backend", "cpu", "--width", "64", "--height", "48"});
  ASSERT_EQ(twenty.exit_code, 0) << describe(twenty);
  EXPECT_NE(twenty.err.find("8 frames in"), std::string::npos) << describe(twenty);  // ceil(0.4 × 20)
  EXPECT_TRUE(fs::exists(dir.file("tw_0007.png")));
  EXPECT_FALSE(fs::exists(dir.file("tw_0008.png")));
  // Frame 2 at 20 fps is t = 0.1 s: frame 1 at 10 fps, pixel for pixel; frame 1 is not.
  EXPECT_EQ(mean_abs_difference(pixels(dir.file("tw_0002.png")), pixels(dir.file("ten_0001.png"))), 0.0);
  EXPECT_GT(mean_abs_difference(pixels(dir.file("tw_0001.png")), pixels(dir.file("ten_0001.png"))), 1e-4);
  // A rate that asks for more frames than a scene may have is a usage error, before any
  // frame is rendered (200 s × 1000 fps = 200,000 frames > 100,000).
  const std::string long_scene = write_scene(dir, R"({"motion": "dance", "fps": 10, "duration_s": 200})");
  ProcessResult many = run_sylva({"render", "--spp", "1", long_scene, "--frames", "0..1", "-o",
                                  dir.file("m_{frame}.png"), "--fps", "1000", "--backend", "cpu"});
  EXPECT_EQ(many.exit_code, 2) << describe(many);
  EXPECT_NE(many.err.find("ask for more than 100000 frames"), std::string::npos) << describe(many);
  EXPECT_FALSE(fs::exists(dir.file("m_0000.png")));
}

TEST(RenderFrames, OnOpenGlTheRendererReuploadsEachPoseAndMatchesTheCpu) {
  TempDir dir;
  const std::string scene = write_scene(dir, kDance);
  ProcessResult gl = run_sylva({"render", "--spp", "1", scene, "--frames", "0..3", "-o", dir.file("gl_{frame}.png"), "--backend", "gl"});
  if (gl_missing(gl)) SYLVA_SKIP_WITHOUT_GL("no OpenGL: " << gl.err);
  ASSERT_EQ(gl.exit_code, 0) << describe(gl);
  EXPECT_NE(gl.err.find("re-skin + upload"), std::string::npos) << describe(gl);  // 3 updates, one renderer
  ProcessResult cpu = run_sylva({"render", "--spp", "1", scene, "--frames", "0..3", "-o", dir.file("cpu_{frame}.png"), "--backend", "cpu"});
  ASSERT_EQ(cpu.exit_code, 0) << describe(cpu);
  // Frame 3 drawn by GL is the CPU's frame 3 (the backends' usual 1–2/255), much closer to
  // it than to the rest pose: the moved segment records reached the GPU.
  const std::vector<float> gl3 = pixels(dir.file("gl_0003.png"));
  const double same_pose = mean_abs_difference(gl3, pixels(dir.file("cpu_0003.png")));
  const double rest_pose = mean_abs_difference(gl3, pixels(dir.file("cpu_0000.png")));
  std::printf("[ frames ] GL frame 3 against the CPU's frame 3: %.5f, against its frame 0: %.5f\n", same_pose, rest_pose);
  EXPECT_LT(same_pose, 3.0 / 255);
  EXPECT_LT(same_pose * 3, rest_pose);
}

TEST(RenderFrames, AGrammarGrowsOneDerivationStepPerFrameSeenByTheLastFramesCamera) {
  TempDir dir;
  ProcessResult r = run_sylva({"render", "--spp", "1", kElm, "--frames", "4..6", "-o", dir.file("g_{frame}.png"), "--width", "48",
                               "--height", "36", "--backend", "cpu"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  for (const char* f : {"g_0004.png", "g_0005.png", "g_0006.png"}) EXPECT_TRUE(fs::exists(dir.file(f))) << f;
  // The last frame is the grammar grown 6 steps in its own default view.
  ProcessResult six = run_sylva({"render", "--spp", "1", kElm, "-n", "6", "-o", dir.file("six.png"), "--width", "48", "--height", "36",
                                 "--backend", "cpu"});
  ASSERT_EQ(six.exit_code, 0) << describe(six);
  EXPECT_EQ(mean_abs_difference(pixels(dir.file("g_0006.png")), pixels(dir.file("six.png"))), 0.0);
  EXPECT_GT(mean_abs_difference(pixels(dir.file("g_0004.png")), pixels(dir.file("six.png"))), 1e-4);
  // Frame 0 is the axiom: no segment yet, sky and ground only — still a picture.
  ProcessResult axiom = run_sylva({"render", "--spp", "1", kElm, "--frames", "0", "-o", dir.file("a_{frame}.png"), "--width", "16",
                                   "--height", "12"});
  EXPECT_EQ(axiom.exit_code, 0) << describe(axiom);
  EXPECT_TRUE(fs::exists(dir.file("a_0000.png")));
}

// Issue 31 §3: `--frames all` stops at the first frame that already shows the grown plant
// (here step 3 of 8: A stops rewriting itself), so a growth movie has no static tail; an
// explicit range is rendered whole.
TEST(RenderFrames, AllFramesOfAGrowthStopWhenThePlantHasStoppedGrowing) {
  TempDir dir;
  dir.write("stops.lsys", "derivation length: 8\naxiom: A(0)\nA(n) : n < 3 -> F(1) A(n+1)\n");
  ProcessResult all = run_sylva({"render", "--spp", "1", dir.file("stops.lsys"), "--frames", "all", "-o",
                                 dir.file("all/g_{frame}.png"), "--width", "24", "--height", "18", "--backend", "cpu"});
  ASSERT_EQ(all.exit_code, 0) << describe(all);
  EXPECT_EQ(list_dir(dir.file("all")),
            (std::vector<std::string>{"g_0000.png", "g_0001.png", "g_0002.png", "g_0003.png"}));
  EXPECT_NE(all.err.find("frame 3 already shows the grown plants: frames 4..8 would repeat it and are left out"),
            std::string::npos)
      << all.err;
  EXPECT_NE(all.err.find("4 frames in"), std::string::npos) << all.err;
  ProcessResult range = run_sylva({"render", "--spp", "1", dir.file("stops.lsys"), "--frames", "0..8", "-o",
                                   dir.file("range/g_{frame}.png"), "--width", "24", "--height", "18", "--backend",
                                   "cpu"});
  ASSERT_EQ(range.exit_code, 0) << describe(range);
  EXPECT_EQ(list_dir(dir.file("range")).size(), 9u);
  EXPECT_EQ(mean_abs_difference(pixels(dir.file("range/g_0008.png")), pixels(dir.file("all/g_0003.png"))), 0.0);
}

// Issue 31 §3: --substeps K puts K frames between two derivation steps; frame K·n is step
// n's picture exactly, the frames between show the new internode growing out.
TEST(RenderFrames, SubstepsGrowWhatIsNewOutBetweenTwoSteps) {
  TempDir dir;
  dir.write("stops.lsys", "derivation length: 8\naxiom: A(0)\nA(n) : n < 3 -> F(1) A(n+1)\n");
  auto render = [&](const std::string& folder, const std::vector<std::string>& more) {
    std::vector<std::string> args = {"render", "--spp", "1", dir.file("stops.lsys"), "-o",
                                     dir.file(folder + "/g_{frame}.png"), "--width", "96", "--height", "72",
                                     "--backend", "cpu", "--frames"};
    args.insert(args.end(), more.begin(), more.end());
    return run_sylva(args);
  };
  ProcessResult halves = render("halves", {"all", "--substeps", "2"});
  ASSERT_EQ(halves.exit_code, 0) << describe(halves);
  EXPECT_EQ(list_dir(dir.file("halves")).size(), 7u) << "steps 0..3 at two frames a step, then grown";
  ProcessResult whole = render("whole", {"all"});
  ASSERT_EQ(whole.exit_code, 0) << describe(whole);
  for (int step = 0; step <= 3; ++step) {
    const std::string a = dir.file("halves/g_000" + std::to_string(2 * step) + ".png");
    const std::string b = dir.file("whole/g_000" + std::to_string(step) + ".png");
    EXPECT_EQ(mean_abs_difference(pixels(a), pixels(b)), 0.0) << step;
  }
  for (int k : {1, 3, 5}) {  // half-way frames: neither step
    const std::vector<float> mid = pixels(dir.file("halves/g_000" + std::to_string(k) + ".png"));
    EXPECT_GT(mean_abs_difference(mid, pixels(dir.file("halves/g_000" + std::to_string(k - 1) + ".png"))), 0.0) << k;
    EXPECT_GT(mean_abs_difference(mid, pixels(dir.file("halves/g_000" + std::to_string(k + 1) + ".png"))), 0.0) << k;
  }
  // Only a growth has steps; out of range is a usage error.
  const std::string dancing = std::string(SYLVA_SOURCE_DIR) + "/presets/scenes/dancing_cacti.scene.json";
  ProcessResult moving = run_sylva({"render", dancing, "-o", dir.file("d/f_{frame}.png"), "--frames", "0..1",
                                    "--substeps", "2", "--backend", "cpu", "--width", "16", "--height", "12"});
  EXPECT_EQ(moving.exit_code, 2) << describe(moving);
  EXPECT_NE(moving.err.find("--substeps applies to a growth"), std::string::npos) << describe(moving);
  EXPECT_EQ(render("bad", {"all", "--substeps", "0"}).exit_code, 2);
  EXPECT_EQ(render("bad", {"all", "--substeps", "101"}).exit_code, 2);
}

TEST(RenderFrames, ASceneWithoutAnimationGrowsItsPlantsInLockstepInItsLight) {
  // docs/animation.md: frame k is every plant grown min(k, its derivation length) steps,
  // all in lockstep in the scene's light (light.md), seen by the scene's camera. Two
  // competing trees (presets/light/competition.lsys: every step reads its ?E answers), one
  // of them stopped at 3 steps by its own key.
  TempDir dir;
  fs::copy_file(std::string(SYLVA_SOURCE_DIR) + "/presets/light/competition.lsys", dir.file("competition.lsys"));
  auto scene = [&](const std::string& name, const std::string& steps) {
    return dir.write(name, R"({"image": {"width": 48, "height": 36},
      "camera": {"eye": [0, 1.5, 6], "target": [0, 1, 0]},
      "environment": {"photons": 20000, "every": 1, "seed": 3},
      "plants": [{"grammar": "competition.lsys", "position": [-0.5, 0, 0], "steps": )" + steps + R"(},
                 {"grammar": "competition.lsys", "position": [0.5, 0, 0], "steps": 3}]})");
  };
  const std::string growing = scene("grow.scene.json", "5");
  ProcessResult r = run_sylva({"render", "--spp", "1", growing, "--frames", "all", "-o", dir.file("g_{frame}.png"),
                               "--backend", "cpu"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  // all: frames 0 to the longest derivation, 5.
  EXPECT_NE(r.err.find("6 frames in"), std::string::npos) << describe(r);
  EXPECT_TRUE(fs::exists(dir.file("g_0005.png")));
  EXPECT_FALSE(fs::exists(dir.file("g_0006.png")));
  // Frame 4 is the scene with its first tree grown 4 steps (the second stopped at 3):
  // the same words as the whole growth's at step 4, light answers included.
  ProcessResult four = run_sylva({"render", "--spp", "1", scene("four.scene.json", "4"), "-o", dir.file("four.png"),
                                  "--backend", "cpu"});
  ASSERT_EQ(four.exit_code, 0) << describe(four);
  EXPECT_EQ(mean_abs_difference(pixels(dir.file("g_0004.png")), pixels(dir.file("four.png"))), 0.0);
  // The last frame is the still scene's picture; earlier frames are not.
  ProcessResult still = run_sylva({"render", "--spp", "1", growing, "-o", dir.file("still.png"), "--backend", "cpu"});
  ASSERT_EQ(still.exit_code, 0) << describe(still);
  EXPECT_EQ(mean_abs_difference(pixels(dir.file("g_0005.png")), pixels(dir.file("still.png"))), 0.0);
  EXPECT_GT(mean_abs_difference(pixels(dir.file("g_0004.png")), pixels(dir.file("still.png"))), 1e-4);
  EXPECT_GT(mean_abs_difference(pixels(dir.file("g_0002.png")), pixels(dir.file("g_0004.png"))), 1e-4);
}

TEST(RenderFrames, TheVideoIsEncodedWithFfmpegOrRefusedBeforeAnyFrame) {
  TempDir dir;
  const std::string scene = write_scene(dir, kDance);
  // Without ffmpeg on PATH: exit 1 saying so, and nothing rendered.
  ProcessResult none = run_process({"/usr/bin/env", "PATH=" + dir.path().string() + "/no-such-folder", SYLVA_BINARY, "render",
                                    scene, "--frames", "0..1", "-o", dir.file("n_{frame}.png"), "--video",
                                    dir.file("n.mp4"), "--backend", "cpu"});
  EXPECT_EQ(none.exit_code, 1) << describe(none);
  EXPECT_NE(none.err.find("--video needs ffmpeg"), std::string::npos) << describe(none);
  EXPECT_FALSE(fs::exists(dir.file("n_0000.png")));
  EXPECT_FALSE(fs::exists(dir.file("n.mp4")));
  if (run_process({"/bin/sh", "-c", "command -v ffmpeg"}).exit_code != 0) SYLVA_SKIP_WITHOUT_TOOL("ffmpeg is not installed");
  ProcessResult r = run_sylva({"render", "--spp", "1", scene, "--frames", "0..3", "-o", dir.file("v_{frame}.png"), "--video",
                               dir.file("dance.mp4"), "--fps", "12", "--backend", "cpu"});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.err.find("4 frames at 12 fps"), std::string::npos) << describe(r);
  std::ifstream video(dir.file("dance.mp4"), std::ios::binary);
  std::string head(12, '\0');
  video.read(head.data(), 12);
  EXPECT_EQ(head.substr(4, 4), "ftyp") << "not an MP4 file";
  // ffprobe, installed with ffmpeg, counts the frames and the rate.
  ProcessResult probe = run_process({"ffprobe", "-v", "error", "-select_streams", "v:0", "-count_frames", "-show_entries",
                                     "stream=nb_read_frames,r_frame_rate,width,height", "-of", "csv=p=0",
                                     dir.file("dance.mp4")});
  EXPECT_EQ(probe.exit_code, 0) << describe(probe);
  EXPECT_EQ(probe.out, "64,48,12/1,4\n") << describe(probe);
  // No temporary is left beside the video.
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(RenderFrames, BadFrameRequestsAreUsageErrors) {
  TempDir dir;
  const std::string scene = write_scene(dir, kDance);
  const std::string empty = dir.write("empty.scene.json", R"({"plants": []})");
  fs::copy_file(kElm, dir.file("elm.lsys"));
  ASSERT_EQ(run_sylva({"grow", kElm, "-o", dir.file("elm.skel.json")}).exit_code, 0);
  struct Case {
    std::vector<std::string> args;
    const char* message;
  };
  const std::string f = dir.file("f_{frame}.png");
  for (const Case& c : std::vector<Case>{
           {{scene, "--frames", "0..3", "-o", dir.file("f.png")}, "must hold {frame}"},
           {{scene, "-o", f}, "holds {frame}: give --frames"},
           {{scene, "--frames", "5..2", "-o", f}, "the range is empty"},
           {{scene, "--frames", "0..100000", "-o", f}, "at most 100000 frames"},
           {{scene, "--frames", "x", "-o", f}, "expected all, a frame N or a range A..B"},
           {{scene, "--frames", "-1..2", "-o", f}, "expected all, a frame N or a range A..B"},
           {{empty, "--frames", "0..1", "-o", f}, "has no animation key and no plant that grows"},
           {{dir.file("elm.skel.json"), "--frames", "0..1", "-o", f}, "--frames applies to a .scene.json scene"},
           {{dir.file("elm.lsys"), "--frames", "0..1", "-n", "3", "-o", f}, "leave out -n"},
           {{scene, "--frames", "0..1", "-o", f, "--video", dir.file("v.avi")}, "expected a .mp4"},
           {{scene, "--frames", "0..1", "-o", dir.file("f_{frame}.exr"), "--video", dir.file("v.mp4")}, "PNG frames"},
           {{scene, "--frames", "0..1", "-o", f, "--fps", "0"}, "--fps 0: expected"},
           {{scene, "-o", dir.file("g.png"), "--video", dir.file("v.mp4")}, "apply with --frames only"},
       }) {
    std::vector<std::string> args = {"render"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    ProcessResult r = run_sylva(args);
    EXPECT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.err.find(c.message), std::string::npos) << describe(r);
  }
  EXPECT_FALSE(fs::exists(dir.file("f_0000.png")));
}

}  // namespace
