// batch_test.cpp — the seed pool of app/front/batch.h: every seed once, results serialised
// to the caller without printing, failures named, cancellation stops new seeds.
#include "app/front/batch.h"

#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>
#include <vector>

namespace sylva::cli {
namespace {

TEST(SeedTasks, RunsEverySeedOnceAndReportsEachAsItFinishes) {
  std::vector<uint64_t> reported, counts;
  std::vector<double> fractions;
  const std::vector<uint64_t> failed = run_seed_tasks(
      {10, 29}, 4,
      [](uint64_t seed) {
        SeedTaskResult r;
        if (seed % 7 == 0) r.error = file_diagnostic("", "seed " + std::to_string(seed) + " is unlucky");
        if (seed == 20) throw std::runtime_error("boom");
        return r;
      },
      [&](uint64_t seed, const SeedTaskResult& r, uint64_t done, uint64_t total) {
        reported.push_back(seed);
        counts.push_back(done);
        EXPECT_EQ(total, 20u);
        if (seed == 20) {
          ASSERT_TRUE(r.error);
          EXPECT_EQ(r.error->message, "internal error: boom");
        }
      },
      Progress([&](double f, std::string_view stage) {
        fractions.push_back(f);
        EXPECT_EQ(stage, "batch");
      }));
  EXPECT_EQ(std::set<uint64_t>(reported.begin(), reported.end()).size(), 20u);
  for (size_t i = 0; i < counts.size(); ++i) EXPECT_EQ(counts[i], i + 1);  // done counts 1..N in order
  EXPECT_EQ(failed, (std::vector<uint64_t>{14, 20, 21, 28}));  // sorted
  ASSERT_EQ(fractions.size(), 20u);
  EXPECT_EQ(fractions.back(), 1.0);
}

TEST(SeedTasks, CancellingStopsStartingNewSeeds) {
  std::atomic<bool> cancel{false};
  std::atomic<int> ran{0};
  run_seed_tasks(
      {1, 1000}, 1,
      [&](uint64_t) {
        if (++ran == 5) cancel.store(true);
        return SeedTaskResult{};
      },
      [](uint64_t, const SeedTaskResult&, uint64_t, uint64_t) {}, Progress(&cancel));
  EXPECT_EQ(ran.load(), 5);
}

// A placeholder that '..' undoes gives every value one file (issue 32): refused, naming
// the file they would all write; one that survives normalisation is kept.
TEST(OutputPatterns, APlaceholderThatDotDotUndoesIsRefused) {
  EXPECT_THROW(check_pattern_separates("out/{seed}/../same.skel.json", "{seed}"), UsageError);
  EXPECT_THROW(check_pattern_separates("{frame}/../f.png", "{frame}"), UsageError);
  try {
    check_pattern_separates("out/{seed}/../same.skel.json", "{seed}");
  } catch (const UsageError& e) {
    EXPECT_NE(e.message.find("out/same.skel.json"), std::string::npos) << e.message;
  }
  EXPECT_NO_THROW(check_pattern_separates("out/{seed}/a.skel.json", "{seed}"));
  EXPECT_NO_THROW(check_pattern_separates("./out/../a_{seed}.skel.json", "{seed}"));
  EXPECT_NO_THROW(check_pattern_separates("f/{frame}/../{frame}.png", "{frame}"));
}

}  // namespace
}  // namespace sylva::cli
