// `sylva bench light`: the ?E light's error against closed forms and its time, end to end:
// its CSV, its plot and its usage errors (a smoke test with --quick; the measurement itself
// is docs/benchmarks.md's, never a timed test).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

TEST(BenchLight, QuickRunWritesEveryCaseAndTheCostRow) {
  TempDir dir;
  const std::string csv = dir.file("light.csv"), plot = dir.file("light.png");
  auto r = run_process({SYLVA_BINARY, "bench", "light", "--quick", "--csv", csv, "--plot", plot}, SYLVA_SOURCE_DIR, 600);
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const std::string text = read_file(csv);
  ASSERT_NE(text.find("case,photons,sensors,segments,q_mean,expected,abs_error,std_error,seconds,cpu_seconds,build_seconds\n"),
            std::string::npos)
      << text;
  // case -> (photons -> |error|, std error)
  std::map<std::string, std::map<long, std::pair<double, double>>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("case,", 0) == 0) continue;
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) f.push_back(field);
    ASSERT_EQ(f.size(), 11u) << line;
    rows[f[0]][std::atol(f[1].c_str())] = {std::atof(f[6].c_str()), std::atof(f[7].c_str())};
  }
  for (const char* name : {"open sky", "disc UOC", "disc SOC", "slab L=0.5 0 deg", "slab L=1 30 deg", "slab L=2 30 deg"}) {
    ASSERT_EQ(rows[name].size(), 2u) << name << "\n" << text;
    // At 1e5 photons every case is within 4 of its standard errors plus the slab's own
    // randomness (the leaves are one draw: a few hundredths).
    const auto [error, se] = rows[name][100000];
    EXPECT_LT(error, 4 * se + 0.03) << name << "\n" << text;
    EXPECT_GT(se, 0) << name;
    EXPECT_LT(rows[name][100000].second, rows[name][10000].second) << name << ": more photons, less noise";
  }
  ASSERT_EQ(rows["pine"].size(), 1u) << text;
  EXPECT_NE(r.out.find("pine"), std::string::npos);
  EXPECT_FALSE(read_file(plot).empty());
}

TEST(BenchLight, BadFlagsAreUsageErrors) {
  for (std::vector<std::string> extra : {std::vector<std::string>{"--threads", "x"}, {"--bogus"}, {"presets/pine.lsys"}}) {
    std::vector<std::string> argv = {SYLVA_BINARY, "bench", "light"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto r = run_process(argv, SYLVA_SOURCE_DIR, 60);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
  }
}

}  // namespace
