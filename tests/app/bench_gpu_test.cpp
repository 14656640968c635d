// `sylva bench gpu`: a quick run end to end on whatever EGL gives (llvmpipe in CI) — the
// CSV's columns and rows, the plot, methods the GL backend refuses reported as skipped
// with its reason, and the animated skeletons' uploads. (A smoke test on a tiny image:
// speed figures live in docs/benchmarks.md, never in tests.)
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <fstream>
#include <sstream>
#include <thread>
#include <string>
#include <vector>

#include "core/gl/render_gl.h"
#include "core/scene/scene.h"
#include "core/scene/scene_json.h"
#include "tests/support/process.h"
#include "tests/support/requirements.h"

namespace {

using sylva::GeometryKind;
using sylva::RenderOptions;
using sylva::Scene;

constexpr const char* kGrammar = "presets/saguaro.lsys";
constexpr const char* kScene = "presets/scenes/saguaro.scene.json";

// One CSV line split into fields (RFC 4180 quotes).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') fields.back() += '"', ++i;
    else if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) fields.emplace_back();
    else fields.back() += c;
  }
  return fields;
}

using CsvRow = std::map<std::string, std::string>;

// The CSV's rows by column name, after checking its header; '#' lines are comments.
std::vector<CsvRow> read_csv(const std::string& text, const std::vector<std::string>& expected_columns) {
  std::istringstream in(text);
  std::vector<std::string> columns;
  std::vector<CsvRow> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (columns.empty()) {
      columns = csv_fields(line);
      EXPECT_EQ(columns, expected_columns);
      continue;
    }
    const std::vector<std::string> fields = csv_fields(line);
    EXPECT_EQ(fields.size(), columns.size()) << line;
    CsvRow row;
    for (size_t i = 0; i < std::min(fields.size(), columns.size()); ++i) row[columns[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

double number(const CsvRow& row, const std::string& column) {
  const std::string& text = row.at(column);
  EXPECT_FALSE(text.empty()) << column << " of " << row.at("method");
  return text.empty() ? std::nan("") : std::stod(text);
}

// The geometry options of each method a quick run measures, to ask gl_unsupported the
// question the benchmark asks.
struct ExpectedMethod {
  std::string name;
  GeometryKind kind;
  bool relief;   // frusta: relief-mapped
  int level;     // mesh: GS level
  bool displace; // mesh: GS+R
};

std::optional<std::string> refusal(const Scene& scene, const ExpectedMethod& m) {
  RenderOptions options;
  options.geometry.kind = m.kind;
  options.geometry.relief = m.relief;
  options.geometry.mesh_level = m.level;
  options.geometry.displace = m.displace;
  return sylva::gl_unsupported(scene, options);
}

const std::vector<std::string> kColumns = {
    "device", "gl_renderer", "input", "width", "height", "method", "family", "steps", "bisection", "mesh_level",
    "status", "reason", "frames", "gpu_ms_median", "gpu_ms_p10", "gpu_ms_p90", "fps", "wall_ms_median", "frusta",
    "setup_upload_bytes", "gpu_memory_bytes", "upload_bytes_per_frame", "sway_ms_median", "update_ms_median",
    "reference", "depth_rmse_m", "depth_max_m", "hit_mismatch", "colour_rmse", "colour_max"};

// Runs `sylva bench gpu ARGS --csv --plot` in a fresh folder; nullopt (the test skipped)
// where no OpenGL context can be made. Checks the exit status and the PNG.
std::optional<std::vector<CsvRow>> run_bench_gpu(std::vector<std::string> args) {
  TempDir dir;
  args.insert(args.begin(), {"bench", "gpu"});
  args.insert(args.end(), {"--csv", dir.file("gpu.csv"), "--plot", dir.file("gpu.png")});
  const ProcessResult r = run_sylva(args, SYLVA_SOURCE_DIR, 240);
  EXPECT_FALSE(crashed(r)) << describe(r);
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 context") != std::string::npos) return std::nullopt;
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  if (r.exit_code != 0) return std::vector<CsvRow>{};
  const std::string png = read_file(dir.file("gpu.png"));
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  return read_csv(read_file(dir.file("gpu.csv")), kColumns);
}

// Checks `rows` against `methods` on `scene`, one row each in order: a method
// gl_unsupported refuses is a skipped row carrying its reason; the others are measured.
void expect_rows(const std::vector<CsvRow>& rows, const std::string& input, const Scene& scene,
                 const std::vector<ExpectedMethod>& methods, const std::string& width, const std::string& height,
                 const std::string& frames) {
  ASSERT_EQ(rows.size(), methods.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const CsvRow& row = rows[i];
    const ExpectedMethod& m = methods[i];
    SCOPED_TRACE(input + " " + m.name);
    EXPECT_EQ(row.at("input"), input);
    EXPECT_EQ(row.at("method"), m.name);
    EXPECT_EQ(row.at("width"), width);
    EXPECT_EQ(row.at("height"), height);
    if (row.at("gl_renderer").find("llvmpipe") != std::string::npos) {
      EXPECT_EQ(row.at("device"), "software (llvmpipe)");
    }
    if (const auto why = refusal(scene, m)) {
      EXPECT_EQ(row.at("status"), "skipped");
      EXPECT_EQ(row.at("reason"), *why);
      EXPECT_EQ(row.at("frames"), "0");
      EXPECT_EQ(row.at("gpu_ms_median"), "");
      continue;
    }
    ASSERT_EQ(row.at("status"), "ok") << row.at("reason");
    EXPECT_EQ(row.at("frames"), frames);
    const double median = number(row, "gpu_ms_median");
    EXPECT_GT(median, 0);
    EXPECT_LE(number(row, "gpu_ms_p10"), median);
    EXPECT_GE(number(row, "gpu_ms_p90"), median);
    EXPECT_NEAR(number(row, "fps"), 1e3 / median, 1e-3 * 1e3 / median);
    EXPECT_GT(number(row, "setup_upload_bytes"), 0);
    // 64 bytes a pixel of render targets at least, and a 64-byte record per frustum.
    EXPECT_GE(number(row, "gpu_memory_bytes"),
              64 * number(row, "frusta") + 64 * std::stod(width) * std::stod(height));
    EXPECT_GE(number(row, "depth_rmse_m"), 0);
    EXPECT_GE(number(row, "colour_rmse"), 0);
    if (m.name != "RC anim") {
      EXPECT_EQ(row.at("upload_bytes_per_frame"), "");
    }
  }
}

TEST(BenchGpu, QuickRunOnAGrammarMeasuresEveryMethodTheGlBackendDraws) {
  const auto rows = run_bench_gpu({kGrammar, "--quick"});
  if (!rows) SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine");
  Scene bare;  // the grammar's default scene: one plant, no bark
  bare.plants.resize(1);
  const std::vector<ExpectedMethod> methods = {{"RC", GeometryKind::frusta, false, 0, false},
                                               {"RC no cons. depth", GeometryKind::frusta, false, 0, false},
                                               {"GS m=0", GeometryKind::mesh, false, 0, false},
                                               {"GS m=1", GeometryKind::mesh, false, 1, false},
                                               {"RC anim", GeometryKind::frusta, false, 0, false}};
  expect_rows(*rows, kGrammar, bare, methods, "160", "120", "3");
  if (HasFailure()) return;
  for (const CsvRow& row : *rows) {
    SCOPED_TRACE(row.at("method"));
    EXPECT_EQ(row.at("status"), "ok") << "the GL backend draws a bare grammar's frusta and meshes";
    if (row.at("family").rfind("RC", 0) == 0) {
      // Bare frusta against the CPU's: the GL tests' agreement (99.5 % of pixels), depth
      // to float precision but where the view keeps a crotch's fillet: GL draws its facets,
      // within millimetres of the fillet the CPU marches (docs/joints.md; measured 6.2e-4 m
      // and 7.0e-4 m RMS over the saguaro at 160x120).
      EXPECT_LE(number(row, "hit_mismatch"), 0.005);
      EXPECT_LT(number(row, "depth_rmse_m"), 1.5e-3);
    }
  }
  const CsvRow& anim = rows->back();
  // Every frame re-uploads a 64-byte record per frustum at least, and the last pose drawn
  // agrees with the CPU's drawing of it.
  EXPECT_GE(number(anim, "upload_bytes_per_frame"), 64 * number(anim, "frusta"));
  EXPECT_GE(number(anim, "update_ms_median"), 0);
  EXPECT_GE(number(anim, "sway_ms_median"), 0);
  EXPECT_EQ(anim.at("reference"), "RC at the same pose (CPU)");
  EXPECT_EQ(rows->front().at("reference"), "RC (the scene has no height map) (CPU)");
}

// The relief rows on a scene with a height map, chosen with --methods (a small image and
// one frame: bark textures are slow on a software rasteriser): relief-mapped frusta come
// close to the converged reference, which the bare frusta miss by centimetres.
TEST(BenchGpu, ReliefRowsOnASceneWithAHeightMap) {
  const auto rows = run_bench_gpu(
      {kScene, "--quick", "--methods", "RC+R,GS+R", "--width", "64", "--height", "48", "--frames", "1", "--warmup", "1"});
  if (!rows) SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine");
  const sylva::Expected<sylva::Scene> read = sylva::read_scene_file(std::string(SYLVA_SOURCE_DIR) + "/" + kScene);
  ASSERT_TRUE(read.ok()) << read.error().format();
  const std::vector<ExpectedMethod> methods = {{"RC+R 16x4", GeometryKind::frusta, true, 0, false},
                                               {"GS+R m=0", GeometryKind::mesh, false, 0, true},
                                               {"GS+R m=1", GeometryKind::mesh, false, 1, true}};
  expect_rows(*rows, kScene, *read, methods, "64", "48", "1");
  if (HasFailure() || rows->front().at("status") != "ok") return;
  EXPECT_EQ(rows->front().at("reference"), "RC+R 1024x24 exact v (CPU)");
  EXPECT_LT(number(rows->front(), "depth_rmse_m"), 0.02);
  EXPECT_LE(number(rows->front(), "hit_mismatch"), 0.005);
}

// A scene the GL backend refuses whatever the method: 17 cacti, each with its own bark
// image (it binds at most 16). Every method is a skipped row with the reason, nothing is
// rendered, and the CSV and plot are still written.
TEST(BenchGpu, MethodsTheGlBackendRefusesAreSkippedRowsWithTheReason) {
  TempDir dir;
  const std::string bark = read_file(std::string(SYLVA_SOURCE_DIR) + "/presets/textures/bark.png");
  std::string plants;
  for (int i = 0; i < 17; ++i) {
    const std::string image = "bark" + std::to_string(i) + ".png";
    dir.write(image, bark);
    plants += std::string(i ? ",\n" : "") + "{\"grammar\": \"" + SYLVA_SOURCE_DIR + "/presets/cactus.lsys\", \"seed\": " +
              std::to_string(i + 1) + ", \"position\": [" + std::to_string(2 * (i % 5)) + ", 0, " +
              std::to_string(2 * (i / 5)) + "], \"bark\": {\"albedo\": \"" + image + "\"}}";
  }
  const std::string scene = dir.write("cacti.scene.json", "{\"format\": \"sylva-scene\", \"version\": 1,\n"
                                                          "\"plants\": [" + plants + "]}\n");
  const ProcessResult r = run_sylva({"bench", "gpu", scene, "--quick", "--csv", dir.file("gpu.csv"), "--plot",
                                     dir.file("gpu.png")},
                                    dir.path().string(), 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 context") != std::string::npos)
    SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine: " << r.err);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(r.err.find("CPU reference"), std::string::npos) << "no method ran, so no reference is rendered";
  const std::vector<CsvRow> rows = read_csv(read_file(dir.file("gpu.csv")), kColumns);
  std::vector<std::string> methods;
  for (const CsvRow& row : rows) {
    methods.push_back(row.at("method"));
    EXPECT_EQ(row.at("status"), "skipped") << row.at("method");
    EXPECT_NE(row.at("reason").find("distinct bark images (this scene has 17)"), std::string::npos) << row.at("reason");
    EXPECT_EQ(row.at("frames"), "0");
    EXPECT_EQ(row.at("depth_rmse_m"), "");
  }
  EXPECT_EQ(methods, (std::vector<std::string>{"RC", "RC no cons. depth", "GS m=0", "GS m=1", "RC anim"}));
  EXPECT_NE(r.out.find("RC no cons. depth"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("skipped: the GL backend binds at most 16"), std::string::npos) << r.out;
  EXPECT_EQ(read_file(dir.file("gpu.png")).substr(0, 4), "\x89PNG");
}

TEST(BenchGpu, MethodsCanBeChosenAndAnUnknownFamilyIsAUsageError) {
  const ProcessResult r = run_sylva({"bench", "gpu", kGrammar, "--methods", "RC,bogus"}, SYLVA_SOURCE_DIR);
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_NE(r.err.find("unknown method family 'bogus'"), std::string::npos) << describe(r);
}

TEST(BenchGpu, WithoutOpenGlItExitsOneSayingWhy) {
  // libglvnd finds no EGL vendor library: no context can be made on any machine.
  TempDir dir;
  setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/sylva-test-no-egl-vendor.json", 1);
  const ProcessResult r = run_sylva({"bench", "gpu", std::string(SYLVA_SOURCE_DIR) + "/" + kGrammar, "--quick"},
                                    dir.path().string());
  unsetenv("__EGL_VENDOR_LIBRARY_FILENAMES");
  EXPECT_TRUE(list_dir(dir.path()).empty()) << "nothing written";
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("sylva bench gpu: no OpenGL 4.5 context: "), std::string::npos) << describe(r);
}

// The progress lines on stderr (not a terminal here: plain lines), one per row with the
// time elapsed and, before the last, an estimate of the time left; the finished CSV has no
// partial-run line.
TEST(BenchGpu, EachRowGetsAProgressLineWithElapsedAndTimeLeft) {
  TempDir dir;
  const ProcessResult r = run_sylva({"bench", "gpu", kGrammar, "--quick", "--csv", dir.file("gpu.csv"), "--plot",
                                     dir.file("gpu.png")},
                                    SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 context") != std::string::npos) SYLVA_SKIP_WITHOUT_GL("no OpenGL");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  for (int k = 1; k <= 5; ++k) {
    const std::string head = "sylva bench gpu: row " + std::to_string(k) + "/5 done in ";
    const size_t at = r.err.find(head);
    ASSERT_NE(at, std::string::npos) << head << "\n" << r.err;
    const std::string line = r.err.substr(at, r.err.find('\n', at) - at);
    EXPECT_NE(line.find(" elapsed"), std::string::npos) << line;
    EXPECT_EQ(line.find(" left") != std::string::npos, k < 5) << line;
    EXPECT_EQ(line.find('\x1b'), std::string::npos) << "no terminal, no decoration: " << line;
  }
  EXPECT_NE(r.err.find("(saguaro.lsys 160x120 RC)"), std::string::npos) << r.err;
  const std::string csv = read_file(dir.file("gpu.csv"));
  EXPECT_EQ(csv.find("# partial run"), std::string::npos) << csv;
  EXPECT_NE(csv.find(", quick run\n"), std::string::npos) << csv;
}

// SIGTERM after the first row: the CSV holds the rows done, each complete, and says it
// is a partial run; no temporary file is left beside it.
TEST(BenchGpu, AStoppedRunLeavesAValidCsvOfTheRowsItFinished) {
  TempDir dir;
  const std::string csv = dir.file("gpu.csv");
  std::vector<std::string> argv = {SYLVA_BINARY, "bench", "gpu", "pine", "--quick", "--frames", "20", "--csv", csv,
                                   "--plot", dir.file("gpu.png")};
  std::vector<char*> args;
  for (std::string& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, dir.file("out.txt").c_str(), O_WRONLY | O_CREAT, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, dir.file("err.txt").c_str(), O_WRONLY | O_CREAT, 0644);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, SYLVA_BINARY, &actions, nullptr, args.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Wait for the first row (the column line and one data line), at most 200 s.
  auto rows_in = [](const std::string& text) {
    size_t lines = 0;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines += !line.empty() && line[0] != '#';
    return lines > 0 ? lines - 1 : 0;  // less the column line
  };
  int status = 0;
  bool exited = false;
  for (int i = 0; i < 20000; ++i) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::ifstream in(csv);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (rows_in(text) >= 1) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (exited) {
    const std::string err = read_file(dir.file("err.txt"));
    if (err.find("no OpenGL 4.5 context") != std::string::npos) SYLVA_SKIP_WITHOUT_GL("no OpenGL");
    FAIL() << "the run ended before it could be stopped: " << err;
  }
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  const std::string text = read_file(csv);
  const std::vector<CsvRow> rows = read_csv(text, kColumns);  // checks every row's field count
  ASSERT_GE(rows.size(), 1u) << text;
  ASSERT_LT(rows.size(), 8u) << "the pine's quick run has 8 rows; it was stopped before the last";
  EXPECT_EQ(rows.front().at("method"), "RC");
  for (const CsvRow& row : rows) {
    EXPECT_EQ(row.at("status"), "ok") << row.at("method");
    EXPECT_EQ(row.at("frames"), "20");
    EXPECT_FALSE(row.at("colour_max").empty()) << "the last column is there: " << row.at("method");
  }
  EXPECT_EQ(text.substr(text.rfind("# partial run")),
            "# partial run: " + std::to_string(rows.size()) + " of 8 rows (the run was stopped, or is still running)\n");
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"err.txt", "gpu.csv", "out.txt"}))
      << "no temporary and no plot left";
}

// The default run's settings are what --help says (a small image to keep the test short).
TEST(BenchGpu, TheDefaultRunMeasuresTheSetTheHelpNames) {
  const ProcessResult help = run_sylva({"bench", "gpu", "--help"});
  ASSERT_EQ(help.exit_code, 0) << describe(help);
  EXPECT_NE(help.out.find("The default run: 1024x768, 10 frames after 2, RC, RC-nocd, RC+R 8x0 and 32x4, GS and GS+R\n"
                          "m = 0..2, RC-anim"),
            std::string::npos)
      << help.out;
  EXPECT_NE(help.out.find("--full"), std::string::npos) << help.out;
  const ProcessResult both = run_sylva({"bench", "gpu", "--full", "--quick"});
  EXPECT_EQ(both.exit_code, 2) << describe(both);
  const auto rows = run_bench_gpu({kScene, "--width", "64", "--height", "48"});
  if (!rows) SYLVA_SKIP_WITHOUT_GL("no OpenGL context on this machine");
  const sylva::Expected<sylva::Scene> read = sylva::read_scene_file(std::string(SYLVA_SOURCE_DIR) + "/" + kScene);
  ASSERT_TRUE(read.ok()) << read.error().format();
  std::vector<ExpectedMethod> methods = {{"RC", GeometryKind::frusta, false, 0, false},
                                         {"RC no cons. depth", GeometryKind::frusta, false, 0, false},
                                         {"RC+R 8x0", GeometryKind::frusta, true, 0, false},
                                         {"RC+R 32x4", GeometryKind::frusta, true, 0, false}};
  for (int displace = 0; displace < 2; ++displace)
    for (int m = 0; m <= 2; ++m)
      methods.push_back({std::string(displace ? "GS+R" : "GS") + " m=" + std::to_string(m), GeometryKind::mesh, false, m,
                         displace != 0});
  methods.push_back({"RC anim", GeometryKind::frusta, false, 0, false});
  expect_rows(*rows, kScene, *read, methods, "64", "48", "10");
}

}  // namespace

namespace {

const std::vector<std::string> kFogColumns = {
    "device", "gl_renderer", "input", "width", "height", "method", "mode", "steps", "status", "reason", "frames",
    "fog_ms_median", "cones_ms_median", "frame_gpu_ms_median", "cones", "photons", "overflow_pixels", "fog_rmse",
    "fog_rmse_relative", "fog_bias_relative", "reference"};

// `bench gpu --fog --quick`: the elm grove at 96x72, brute 16 and 64, fast, medium and map,
// each a measured row with the fog pass's GPU time and its RMSE against the CPU reference;
// the cone modes with their cones and cone pass, map with neither. Brute's error falls as its
// steps grow, and map (exact up to its map) beats brute 16.
TEST(BenchGpuFog, QuickRunWritesTheFogRowsWithTimesAndErrors) {
  TempDir dir;
  const ProcessResult r = run_sylva({"bench", "gpu", "--fog", "--quick", "--csv", dir.file("fog.csv"), "--plot",
                                     dir.file("fog.png")},
                                    SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 context") != std::string::npos) SYLVA_SKIP_WITHOUT_GL("no OpenGL");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(read_file(dir.file("fog.png")).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  const std::vector<CsvRow> rows = read_csv(read_file(dir.file("fog.csv")), kFogColumns);
  ASSERT_EQ(rows.size(), 5u);
  const char* const methods[] = {"brute 16", "brute 64", "fast", "medium 64", "map 2048\u00b2"};
  const char* const modes[] = {"brute", "brute", "fast", "medium", "map"};
  for (size_t i = 0; i < rows.size(); ++i) {
    const CsvRow& row = rows[i];
    SCOPED_TRACE(row.at("method"));
    EXPECT_EQ(row.at("method"), methods[i]);
    EXPECT_EQ(row.at("mode"), modes[i]);
    EXPECT_EQ(row.at("status"), "ok") << row.at("reason");
    EXPECT_EQ(row.at("width"), "96");
    EXPECT_EQ(row.at("height"), "72");
    EXPECT_EQ(row.at("frames"), "2");
    EXPECT_NE(row.at("input").find("elm_grove_low_sun"), std::string::npos);
    EXPECT_GT(number(row, "fog_ms_median"), 0.0);
    EXPECT_GE(number(row, "frame_gpu_ms_median"), number(row, "fog_ms_median"));
    EXPECT_GT(number(row, "fog_rmse_relative"), 0.0);
    EXPECT_LT(std::abs(number(row, "fog_bias_relative")), 1.0);
    const bool cones = i == 2 || i == 3;
    EXPECT_EQ(number(row, "cones") > 0, cones);
    EXPECT_EQ(number(row, "cones_ms_median") > 0, cones);
  }
  EXPECT_LT(number(rows[1], "fog_rmse_relative"), number(rows[0], "fog_rmse_relative")) << "64 steps beat 16";
  EXPECT_LT(number(rows[4], "fog_rmse_relative"), number(rows[0], "fog_rmse_relative")) << "map beats brute 16";
}

TEST(BenchGpuFog, AStridedReferenceMeasuresTheErrorOnItsGrid) {
  TempDir dir;
  const ProcessResult r = run_sylva({"bench", "gpu", "--fog", "--quick", "--reference-stride", "4", "--csv",
                                     dir.file("fog.csv"), "--plot", dir.file("fog.png")},
                                    SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  if (r.exit_code == 1 && r.err.find("no OpenGL 4.5 context") != std::string::npos) SYLVA_SKIP_WITHOUT_GL("no OpenGL");
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  // 96x72 every 4th pixel each way: 24 x 18.
  EXPECT_NE(r.err.find("reference of 432 pixels"), std::string::npos) << r.err;
  const std::vector<CsvRow> rows = read_csv(read_file(dir.file("fog.csv")), kFogColumns);
  ASSERT_EQ(rows.size(), 5u);
  for (const CsvRow& row : rows) {
    SCOPED_TRACE(row.at("method"));
    EXPECT_EQ(row.at("status"), "ok") << row.at("reason");
    EXPECT_EQ(row.at("reference"), "CPU fog reference on every 4-th pixel each way");
    EXPECT_GT(number(row, "fog_rmse_relative"), 0.0);
  }
  EXPECT_LT(number(rows[1], "fog_rmse_relative"), number(rows[0], "fog_rmse_relative")) << "64 steps beat 16";
}

}  // namespace
