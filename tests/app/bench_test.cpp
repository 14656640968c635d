// `sylva bench lsystem`: the benchmark runs end to end and prints its summary table.
// (A smoke test on small sizes: speed targets live in the benchmark, never in tests.)
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/support/process.h"

namespace {

TEST(BenchLsystem, QuickRunPrintsEveryCaseAndTheMemcpyBandwidth) {
  auto r = run_process({SYLVA_BINARY, "bench", "lsystem", "--quick", "--benchmark_min_time=0.001"},
                       SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* expected : {"memcpy bandwidth:", "derive/a_abop_1_24a", "derive/b_honda_2_6",
                               "derive/c_abop_1_31a", "turtle/a_abop_1_24a", "turtle/b_honda_2_6",
                               "Mmodules/s", "Msegments/s", "scaling/declare_names/4000",
                               "scaling/right_context_past_branch/real_time_BigO", "scaling/interpret_depth16/1000"})
    EXPECT_NE(r.out.find(expected), std::string::npos) << expected << "\n" << r.out;
}

// Embree user geometry as the renderer traces it hits exactly what sylva's BVH hits: the
// same double ray reaches the same intersect_frustum, so the row must read 0 % and 0 (a
// bench that handed intersect_frustum Embree's float ray read 0.0040 % and 0.000685 on
// the pine at 1024x768).
TEST(BenchRaycast, EmbreeUserGeometryAgreesWithTheBvhExactly) {
  auto r = run_process({SYLVA_BINARY, "bench", "raycast", "--quick", "--width", "1024", "--height", "768"},
                       SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const size_t at = r.out.find("\nembree-user ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string row = r.out.substr(at + 1, r.out.find('\n', at + 1) - at - 1);
  EXPECT_NE(row.find(" 0.0000% "), std::string::npos) << row;
  EXPECT_NE(row.find(" 0 "), std::string::npos) << row;  // depth RMS
}

// Output piped to a file or a log is plain text: colour codes only on a terminal (the
// test's stdout is a pipe).
TEST(BenchLsystem, PipedOutputHasNoColourCodes) {
  auto r = run_process({SYLVA_BINARY, "bench", "lsystem", "--quick", "--benchmark_min_time=0.001",
                        "--benchmark_filter=memcpy"},
                       SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("memcpy"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
}

// Every benchmark answers --help with its own usage on stdout and exit 0, doing no work.
TEST(BenchHelp, EveryBenchmarkPrintsItsUsage) {
  for (const char* name : {"lsystem", "raycast", "geometry", "gpu", "fog", "spp", "studio", "export"}) {
    for (const char* flag : {"--help", "-h"}) {
      auto r = run_process({SYLVA_BINARY, "bench", name, flag}, SYLVA_SOURCE_DIR);
      ASSERT_FALSE(crashed(r)) << name << " " << flag << "\n" << describe(r);
      EXPECT_EQ(r.exit_code, 0) << name << " " << flag << "\n" << describe(r);
      EXPECT_EQ(r.out.rfind(std::string("usage: sylva bench ") + name, 0), 0u) << name << " " << flag << "\n" << r.out;
    }
  }
}

TEST(BenchLsystem, AnUnknownBenchmarkIsAUsageError) {
  auto r = run_process({SYLVA_BINARY, "bench", "nope"}, SYLVA_SOURCE_DIR);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown benchmark 'nope'"), std::string::npos) << r.err;
}

// Flags are checked as everywhere else (exit 2 with the flag named), before any work.
TEST(BenchFlags, BadSizesAndFiltersAreUsageErrors) {
  for (const char* width : {"abc", "0", "-5"}) {
    auto r = run_process({SYLVA_BINARY, "bench", "raycast", "--width", width}, SYLVA_SOURCE_DIR);
    ASSERT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << width << "\n" << describe(r);
    EXPECT_NE(r.err.find(std::string("--width ") + width + ": expected an integer from 1 to 16384"),
              std::string::npos)
        << describe(r);
  }
  auto r = run_process({SYLVA_BINARY, "bench", "lsystem", "--quick", "--benchmark_filter=no_such_case"},
                       SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  EXPECT_NE(r.err.find("no benchmark matches"), std::string::npos) << describe(r);
}

// `sylva bench export --quick`: every variant on the elm and a small instanced scatter,
// each row with its size, its triangles per level falling, its joints where rigged, and
// the CSV holding the same rows.
TEST(BenchExport, QuickRunExportsEveryVariantAndTheScatter) {
  TempDir dir;
  const std::string csv = dir.file("export.csv");
  auto r = run_process({SYLVA_BINARY, "bench", "export", "--quick", "--scatter", "4", "--csv", csv}, SYLVA_SOURCE_DIR, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  for (const char* variant : {"mesh", "rig", "rig+animation", "wind-data", "lod3", "all", "all+meshopt", "instanced+lod3"})
    EXPECT_NE(r.out.find(std::string(" ") + variant + " "), std::string::npos) << variant << "\n" << r.out;
  const std::string text = read_file(csv);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 9) << text;  // header + 8 rows
  EXPECT_NE(text.find("elm,all,"), std::string::npos) << text;
  EXPECT_NE(text.find(",101,38646/8408/3123/4"), std::string::npos) << text;  // joints, falling levels
  EXPECT_NE(text.find("scatter4,instanced+lod3,"), std::string::npos) << text;
  auto bad = run_process({SYLVA_BINARY, "bench", "export", "--scatter", "x"}, SYLVA_SOURCE_DIR);
  EXPECT_EQ(bad.exit_code, 2) << describe(bad);
}

}  // namespace
