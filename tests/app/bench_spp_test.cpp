// `sylva bench spp`: the sampling error of both backends against the samples per pixel,
// end to end on a bundled grammar, its CSV and its usage errors. (A smoke test on a small
// image: the measurement itself is docs/benchmarks.md's, never a timed test.)
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

struct CsvRow {
  std::string input, backend;
  int spp = 0;
  double time_s = 0, rmse = 0, speckle = 0;
};

std::vector<CsvRow> read_rows(const std::string& text) {
  std::vector<CsvRow> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("input,", 0) == 0) continue;
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) f.push_back(field);
    if (f.size() != 7) continue;
    rows.push_back({f[0], f[1], std::atoi(f[2].c_str()), std::atof(f[3].c_str()), std::atof(f[5].c_str()),
                    std::atof(f[6].c_str())});
  }
  return rows;
}

// The pine's needles are sub-pixel at 160x120: one sample per pixel through its centre
// breaks them up, and more samples bring every backend closer to its own converged image.
TEST(BenchSpp, QuickRunMeasuresEveryCountOnBothBackendsAndMoreSamplesConverge) {
  TempDir dir;
  const std::string csv = dir.file("spp.csv"), plot = dir.file("spp.png");
  auto r = run_process({SYLVA_BINARY, "bench", "spp", "presets/pine.lsys", "--quick", "--csv", csv, "--plot", plot},
                       SYLVA_SOURCE_DIR, 600);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const std::string text = read_file(csv);
  EXPECT_NE(text.find("input,backend,spp,time_s,time_ratio,rmse_8bit,speckle\n"), std::string::npos) << text;
  std::map<std::string, std::vector<CsvRow>> by_backend;
  for (const CsvRow& row : read_rows(text)) by_backend[row.backend].push_back(row);
  ASSERT_EQ(by_backend.size(), 2u) << text;  // cpu and gl (llvmpipe where there is no GPU)
  for (const auto& [backend, rows] : by_backend) {
    ASSERT_EQ(rows.size(), 3u) << backend << "\n" << text;  // --quick: 1, 2, 4 against 8
    EXPECT_EQ(rows[0].spp, 1) << text;
    EXPECT_EQ(rows[2].spp, 4) << text;
    EXPECT_EQ(rows[0].input, "pine") << text;
    EXPECT_GT(rows[0].speckle, 0.0) << backend << ": one sample per pixel leaves no pixel broken up?\n" << text;
    EXPECT_LT(rows[2].rmse, rows[0].rmse) << backend << "\n" << text;
    EXPECT_LT(rows[2].speckle, rows[0].speckle) << backend << "\n" << text;
    EXPECT_GT(rows[2].time_s, 0.0) << text;
  }
  EXPECT_NE(r.out.find("smallest spp with speckle <= 0.01 (16/255 steps): pine cpu: "), std::string::npos) << r.out;
  EXPECT_FALSE(read_file(plot).empty());
}

TEST(BenchSpp, BadFlagsAreUsageErrorsBeforeAnyWork) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--spp", "4", "--reference-spp", "4"}, "--reference-spp 4 must exceed every measured count"},
      {{"--backends", "vulkan"}, "--backends: unknown backend 'vulkan'"},
      {{"--max-speckle", "2"}, "--max-speckle needs a fraction from 0 to 1, got '2'"},
      {{"--spp", "0"}, "--spp 0: expected an integer from 1 to 4096"},
      {{"--width", "100"}, "--width and --height go together"},
      {{"no_such_preset"}, "INPUT 'no_such_preset' is neither"},
  };
  for (const auto& [flags, message] : cases) {
    std::vector<std::string> argv = {SYLVA_BINARY, "bench", "spp"};
    argv.insert(argv.end(), flags.begin(), flags.end());
    auto r = run_process(argv, SYLVA_SOURCE_DIR);
    ASSERT_FALSE(crashed(r)) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << flags[0] << "\n" << describe(r);
    EXPECT_NE(r.err.find(message), std::string::npos) << describe(r);
  }
}

}  // namespace
