// bench_rows_test.cpp — app/bench/bench_rows.h: the progress line (plain and decorated, the
// estimate of the time left) and the CSV rewritten after each row with its partial-run
// line until finish().
#include "app/bench/bench_rows.h"

#include <gtest/gtest.h>

#include <string>

#include "tests/support/process.h"

namespace {

using sylva::cli::bench_progress_line;
using sylva::cli::bench_within_row_line;
using sylva::cli::BenchRows;
using sylva::cli::describe_duration;

TEST(BenchRows, DurationsReadAsSecondsMinutesAndHours) {
  EXPECT_EQ(describe_duration(0.84), "0.8 s");
  EXPECT_EQ(describe_duration(42.4), "42 s");
  EXPECT_EQ(describe_duration(185), "3 min 5 s");
  EXPECT_EQ(describe_duration(3720), "1 h 2 min");
  EXPECT_EQ(describe_duration(-1), "?");
}

TEST(BenchRows, TheLineEstimatesTheTimeLeftFromTheMeanRowAndIsDecoratedOnlyOnRequest) {
  // 4 of 10 rows in 60 s: 15 s a row, 6 rows left: 90 s.
  EXPECT_EQ(bench_progress_line("sylva bench gpu", 4, 10, "pine 1024x768 RC", 12, 60, false),
            "sylva bench gpu: row 4/10 done in 12 s (pine 1024x768 RC); 1 min 0 s elapsed, about 1 min 30 s left");
  EXPECT_EQ(bench_progress_line("x", 10, 10, "last", 1, 100, false), "x: row 10/10 done in 1.0 s (last); 1 min 40 s elapsed");
  const std::string decorated = bench_progress_line("x", 5, 10, "w", 1, 10, true);
  EXPECT_EQ(decorated, "x: \x1b[1mrow 5/10\x1b[0m [##########..........] done in 1.0 s (w); 10 s elapsed, about 10 s left");
}

TEST(BenchRows, TheLineWithinALongRowEstimatesWhatIsLeftOfIt) {
  // 25 % of the reference in 2 min: about 6 min left in it.
  EXPECT_EQ(bench_within_row_line("sylva bench fog", 1, 45, "reference, 64 steps", 0.25, 120, 130),
            "sylva bench fog: row 1/45 (reference, 64 steps) 25 % in 2 min 0 s, about 6 min 0 s left in it; "
            "2 min 10 s elapsed");
  EXPECT_EQ(bench_within_row_line("x", 3, 4, "w", 0, 5, 9), "x: row 3/4 (w) 0 % in 5.0 s; 9.0 s elapsed");
}

TEST(BenchRows, TheCsvHoldsTheRowsDoneAndSaysItIsPartialUntilFinished) {
  TempDir dir;
  const std::string path = dir.file("rows.csv");
  BenchRows rows("t", path, "# test\na,b\n", 3, false);
  ASSERT_TRUE(rows.start().ok());
  EXPECT_EQ(read_file(path), "# test\na,b\n# partial run: 0 of 3 rows (the run was stopped, or is still running)\n");
  ASSERT_TRUE(rows.add("1,2\n", "first").ok());
  ASSERT_TRUE(rows.add("3,4\n", "second").ok());
  EXPECT_EQ(read_file(path),
            "# test\na,b\n1,2\n3,4\n# partial run: 2 of 3 rows (the run was stopped, or is still running)\n");
  ASSERT_TRUE(rows.add("5,6\n", "third").ok());
  ASSERT_TRUE(rows.finish().ok());
  EXPECT_EQ(read_file(path), "# test\na,b\n1,2\n3,4\n5,6\n");
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"rows.csv"}) << "no temporary left";
  // A folder that does not exist: start() fails naming the file, and nothing runs.
  BenchRows nowhere("t", dir.file("no/such/rows.csv"), "a\n", 1, false);
  const sylva::Status failed = nowhere.start();
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.error().format().find("no/such/rows.csv"), std::string::npos) << failed.error().format();
}

}  // namespace
