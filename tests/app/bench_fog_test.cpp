// `sylva bench fog`: photons and cones end to end on a bundled scene, the CSVs' columns,
// and its usage errors. (A smoke test on small sizes: speed targets live in the benchmark
// and docs/benchmarks.md, never in tests.)
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "tests/support/process.h"

namespace {

size_t count_lines_starting(const std::string& text, const std::string& prefix) {
  std::istringstream in(text);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.rfind(prefix, 0) == 0;
  return n;
}

TEST(BenchFog, QuickRunWritesEveryModesRowsTheTimeTableAndThePlot) {
  TempDir dir;
  const std::string csv = dir.file("grove.fog.csv"), plot = dir.file("grove.fog.png");
  auto r = run_process({SYLVA_BINARY, "bench", "fog", "presets/scenes/elm_grove_low_sun.scene.json", "--quick",
                        "--csv", csv, "--plot", plot},
                       SYLVA_SOURCE_DIR, 600);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.out.find("M photons/s per core"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("us/ray"), std::string::npos) << r.out;  // the cone query
  EXPECT_NE(r.err.find("cone parameters (automatic)"), std::string::npos) << r.err;
  // Issue 32: a progress line per row; the plan counts every row the run measures. The
  // CSV's rows (cones, brute, medium, refined, fast and map rows) plus the reference.
  const std::string csv_text = read_file(csv);
  const size_t csv_rows = count_lines_starting(csv_text, "") - count_lines_starting(csv_text, "#") - 1;  // less the columns
  const std::string last = "sylva bench fog: row " + std::to_string(csv_rows + 1) + "/" + std::to_string(csv_rows + 1) + " done";
  EXPECT_NE(r.err.find("sylva bench fog: row 1/" + std::to_string(csv_rows + 1) + " done in "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(reference, 8 steps)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(last), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("/" + std::to_string(csv_rows + 2) + " done"), std::string::npos) << r.err;
  const std::string rows = read_file(csv);
  EXPECT_NE(rows.find("mode,steps,photons,seed,photon_s,cone_s,render_s,total_s,rmse,bias,cones\n"), std::string::npos)
      << rows;
  // --quick: 2 seeds of brute 8 and 32, cones of 1e4 and 1e5 photons with automatic
  // and fixed parameters, medium and refined at 16 steps and fast on each, map on each.
  EXPECT_EQ(count_lines_starting(rows, "brute,8,0,"), 2u) << rows;
  EXPECT_EQ(count_lines_starting(rows, "brute,32,0,"), 2u) << rows;
  for (const char* kind : {"auto", "fixed"}) {
    const std::string k = kind;
    EXPECT_EQ(count_lines_starting(rows, "cones-" + k + ",0,10000,"), 2u) << rows;
    EXPECT_EQ(count_lines_starting(rows, "medium-" + k + ",16,100000,"), 2u) << rows;
    EXPECT_EQ(count_lines_starting(rows, "refined-" + k + ",16,100000,"), 2u) << rows;
    EXPECT_EQ(count_lines_starting(rows, "fast-" + k + ",0,10000,"), 2u) << rows;
  }
  // Mode map at 256² texels: one map, and four over the grove's sun disc, on each photon
  // count's tiles (no cones: one row per seed, not per cone parameters).
  for (const char* photons : {"10000", "100000"}) {
    EXPECT_EQ(count_lines_starting(rows, std::string("map1,256,") + photons + ","), 2u) << rows;
    EXPECT_EQ(count_lines_starting(rows, std::string("map4,256,") + photons + ","), 2u) << rows;
  }
  EXPECT_EQ(rows.find("mapcones"), std::string::npos) << rows;  // only with --map-variants
  EXPECT_NE(r.out.find("4 maps of 256²"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("speed-up over brute at equal RMSE"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("time (s, mean over seeds, photons and cones included) to reach the RMSE of"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("fast-auto bias floor"), std::string::npos) << r.out;
  EXPECT_FALSE(read_file(plot).empty());
  const std::string cones = read_file(dir.file("grove.fog-cones.csv"));
  EXPECT_NE(cones.find("photons,seed,params_kind,photon_s,cone_s,params_s,cpu_s,params,vectors,covered,cones,"
                       "missed_shadow,covered_lit,coverage_points,shadowed_points,query_us\n"),
            std::string::npos)
      << cones;
  EXPECT_EQ(count_lines_starting(cones, "100000,"), 4u) << cones;  // 2 seeds × auto, fixed
}

TEST(BenchFog, AStridedReferenceMeasuresOnItsGridAndTimesTheWholeImage) {
  TempDir dir;
  const std::string csv = dir.file("grove.fog.csv");
  auto r = run_process({SYLVA_BINARY, "bench", "fog", "presets/scenes/elm_grove_low_sun.scene.json", "--quick",
                        "--modes", "brute", "--photons", "10000", "--reference-stride", "4", "--csv", csv, "--plot",
                        dir.file("grove.fog.png")},
                       SYLVA_SOURCE_DIR, 600);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  // 64x48 every 4th pixel each way: 16 x 12.
  EXPECT_NE(r.out.find("192 pixels (stride 4)"), std::string::npos) << r.out;
  const std::string rows = read_file(csv);
  EXPECT_NE(rows.find("64x48, "), std::string::npos) << rows;
  EXPECT_NE(rows.find("on every 4-th pixel each way"), std::string::npos) << rows;
  EXPECT_EQ(count_lines_starting(rows, "brute,8,0,"), 2u) << rows;
}

TEST(BenchFog, AMergedRunJoinsTheTablesAndASettingMeasuredAgainReplacesItsRows) {
  TempDir dir;
  const std::string scene = "presets/scenes/elm_grove_low_sun.scene.json";
  const std::string first = dir.file("first.csv"), second = dir.file("second.csv");
  auto run = [&](std::vector<std::string> more) {
    std::vector<std::string> argv = {SYLVA_BINARY, "bench", "fog", scene, "--quick", "--clock", "cpu",
                                     "--photons", "10000", "--plot", dir.file("p.png")};
    argv.insert(argv.end(), more.begin(), more.end());
    return run_process(argv, SYLVA_SOURCE_DIR, 600);
  };
  auto a = run({"--modes", "brute", "--csv", first});
  ASSERT_EQ(a.exit_code, 0) << describe(a);
  const std::string first_rows = read_file(first);
  EXPECT_NE(first_rows.find("each way, CPU clock\n"), std::string::npos) << first_rows;
  auto b = run({"--modes", "brute,fast", "--brute-steps", "32", "--merge", first, "--csv", second});
  ASSERT_EQ(b.exit_code, 0) << describe(b);
  const std::string rows = read_file(second);
  // brute 8 comes from the first run only, brute 32 from the second only (it replaced the
  // first's), the cones of 1e4 photons from the second, fast from the second.
  EXPECT_EQ(count_lines_starting(rows, "brute,8,0,"), 2u) << rows;
  EXPECT_EQ(count_lines_starting(rows, "brute,32,0,"), 2u) << rows;
  EXPECT_EQ(count_lines_starting(rows, "cones-auto,0,10000,"), 2u) << rows;
  EXPECT_EQ(count_lines_starting(rows, "fast-fixed,0,10000,"), 2u) << rows;
  EXPECT_NE(b.out.find("merged 2 rows of 1 file(s), 6 replaced by this run's"), std::string::npos) << b.out;
  // The time table's targets include brute 8, which only the merged file measured.
  EXPECT_NE(b.out.find("brute 8"), std::string::npos) << b.out;
  // A file from another setting (here: the wall clock) is refused before anything runs,
  // at its first line.
  auto c = run_process({SYLVA_BINARY, "bench", "fog", scene, "--quick", "--modes", "fast", "--merge", first,
                        "--csv", dir.file("third.csv")},
                       SYLVA_SOURCE_DIR, 600);
  EXPECT_EQ(c.exit_code, 1) << describe(c);
  EXPECT_NE(c.err.find(first + ":1:1: error: was written by another run setting"), std::string::npos) << c.err;
}

TEST(BenchFog, BadConeParametersAndPhotonCountsAreUsageErrors) {
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--cone-params", "1,2,3"}, {"--cone-params", "16,8,24,4"},  // p1 < p3 + 1
        {"--cone-params", "96,8,24,4,x"}, {"--photons", "0"}, {"--photons", "1e5"}, {"--seeds", "0"},
        {"--modes", "brute,slow"}, {"--brute-steps", "0"}, {"--reference-stride", "0"},
        {"--clock", "sundial"}}) {
    std::vector<std::string> argv = {SYLVA_BINARY, "bench", "fog", "presets/scenes/pine.scene.json"};
    argv.insert(argv.end(), bad.begin(), bad.end());
    auto r = run_process(argv, SYLVA_SOURCE_DIR);
    EXPECT_EQ(r.exit_code, 2) << bad[0] << " " << bad[1] << "\n" << describe(r);
  }
}

}  // namespace
