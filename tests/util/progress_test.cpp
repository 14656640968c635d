// Tests for core/util/progress.h: what a callback sees (monotone, serialised, parts mapped
// onto the whole) and what cancellation looks like.
#include "core/util/progress.h"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace sylva {
namespace {

struct Recorder {
  std::vector<std::pair<double, std::string>> calls;
  Progress progress(const std::atomic<bool>* cancel = nullptr) {
    return Progress([this](double f, std::string_view stage) { calls.emplace_back(f, std::string(stage)); }, cancel);
  }
};

TEST(Progress, ADefaultProgressReportsNothingAndIsNeverCancelled) {
  const Progress none;
  EXPECT_FALSE(none.cancelled());
  EXPECT_FALSE(none.reporting());
  none.report(0.5, "derive");  // no callback: nothing happens
  none.part(0.2, 0.4).report(1, "turtle");
}

TEST(Progress, ReportsReachTheCallbackClampedToTheUnitInterval) {
  Recorder r;
  const Progress p = r.progress();
  EXPECT_TRUE(p.reporting());
  p.report(0.25, "derive");
  p.report(2, "derive");
  ASSERT_EQ(r.calls.size(), 2u);
  EXPECT_EQ(r.calls[0], (std::pair<double, std::string>{0.25, "derive"}));
  EXPECT_EQ(r.calls[1].first, 1.0);
}

TEST(Progress, AReportSmallerThanTheLastIsDropped) {
  Recorder r;
  const Progress p = r.progress();
  p.report(0.5, "render");
  p.report(0.4, "render");
  p.report(0.5, "render");
  p.report(0.6, "render");
  ASSERT_EQ(r.calls.size(), 3u);
  EXPECT_EQ(r.calls[1].first, 0.5);
  EXPECT_EQ(r.calls[2].first, 0.6);
}

TEST(Progress, PartsMapTheirFractionOntoTheirShareOfTheWhole) {
  Recorder r;
  const Progress whole = r.progress();
  const Progress derive = whole.part(0, 0.6), turtle = whole.part(0.6, 1);
  derive.report(0.5, "derive");
  derive.report(1, "derive");
  const Progress half_of_turtle = turtle.part(0.5, 1);  // parts of parts compose
  half_of_turtle.report(0.5, "turtle");
  turtle.report(1, "turtle");
  ASSERT_EQ(r.calls.size(), 4u);
  EXPECT_DOUBLE_EQ(r.calls[0].first, 0.3);
  EXPECT_DOUBLE_EQ(r.calls[1].first, 0.6);
  EXPECT_DOUBLE_EQ(r.calls[2].first, 0.9);
  EXPECT_EQ(r.calls[3].first, 1.0);
}

TEST(Progress, CallsFromManyThreadsAreSerialisedAndMonotone) {
  std::atomic<int> inside{0};
  bool overlapped = false;
  std::vector<double> seen;
  const Progress p([&](double f, std::string_view) {
    if (inside.fetch_add(1) != 0) overlapped = true;
    seen.push_back(f);
    inside.fetch_sub(1);
  });
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 2000; ++i) p.report((i * 4 + t) / 8000.0, "render");
    });
  for (std::thread& t : threads) t.join();
  EXPECT_FALSE(overlapped);
  ASSERT_FALSE(seen.empty());
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_LE(seen[i - 1], seen[i]);
}

TEST(Progress, CancellationFollowsTheFlagInEveryPart) {
  std::atomic<bool> cancel{false};
  const Progress p(&cancel);
  const Progress part = p.part(0.5, 1);
  EXPECT_FALSE(p.cancelled());
  cancel.store(true);
  EXPECT_TRUE(p.cancelled());
  EXPECT_TRUE(part.cancelled());
  EXPECT_FALSE(p.reporting());
}

}  // namespace
}  // namespace sylva
