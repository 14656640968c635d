// studio_parts_test.cpp — the studio's pieces without a UI: the #define lines the
// parameter panel reads and writes, the undo history, and the worker's mailbox.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include <glm/geometric.hpp>

#include "app/studio/code_editor.h"
#include "app/studio/define_controls.h"
#include "app/studio/grow_worker.h"
#include "app/studio/orbit_camera.h"
#include "app/studio/undo_history.h"

namespace sylva::studio {
namespace {

TEST(DefineControls, FindsValuesAndRangeAnnotations) {
  const std::string text =
      "# knobs\n"
      "#define ANGLE 22.5 /* [0, 90] */\n"
      "  #define LIMBS 3 /* [1, 8, 1] */ more text\n"
      "#define EXPR 2*ANGLE\n"
      "#define BAD 1 /* [5, 1] */\n"
      "axiom: F\n";
  const std::vector<DefineLine> d = scan_defines(text);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[0].name, "ANGLE");
  EXPECT_EQ(d[0].line, 2u);
  EXPECT_EQ(d[0].value_text, "22.5");
  ASSERT_TRUE(d[0].has_range());
  EXPECT_EQ(*d[0].min, 0);
  EXPECT_EQ(*d[0].max, 90);
  EXPECT_FALSE(d[0].step);
  EXPECT_EQ(d[1].name, "LIMBS");
  EXPECT_EQ(*d[1].step, 1);
  EXPECT_EQ(d[2].value_text, "2*ANGLE");
  EXPECT_FALSE(d[2].has_range());
  EXPECT_FALSE(d[3].has_range()) << "min >= max is no range: a typed field";
}

TEST(DefineControls, ACpfgFilesCommentEndsAValueAndAFunctionLikeMacroHasNone) {
  // docs/cpfg.md: cpfg files take C's comments; a macro with parameters is no value to set.
  const std::string text = "#define N 7 // steps\n#define BR(a) [+(a)F]\n#define LEN 2 /* [1, 4] */ // metres\n";
  const std::vector<DefineLine> d = scan_defines(text);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].name, "N");
  EXPECT_EQ(d[0].value_text, "7");
  EXPECT_EQ(with_define_value(text, d[0], 9), "#define N 9 // steps\n#define BR(a) [+(a)F]\n#define LEN 2 /* [1, 4] */ // metres\n");
  EXPECT_EQ(d[1].name, "LEN");
  EXPECT_TRUE(d[1].has_range());
}

TEST(DefineControls, WritingAValueChangesOnlyTheValue) {
  const std::string text = "#define ANGLE 22.5 /* [0, 90] */\n#define N 3\n";
  const std::vector<DefineLine> d = scan_defines(text);
  EXPECT_EQ(with_define_value(text, d[0], 0.1), "#define ANGLE 0.1 /* [0, 90] */\n#define N 3\n");
  EXPECT_EQ(with_define_value(text, d[1], 12), "#define ANGLE 22.5 /* [0, 90] */\n#define N 12\n");
}

TEST(DefineControls, ASliderValueIsTheShortestDecimalItsResolutionTellsApart) {
  // Issue 31 §5: "Write to text" wrote 6.1363638043403625 from a slider 300 px wide over [0, 10].
  EXPECT_EQ(shortest(slider_value(6.1363638043403625, 10.0 / 300)), "6.14");
  EXPECT_EQ(shortest(slider_value(6.1363638043403625, 1.0)), "6");
  EXPECT_EQ(shortest(slider_value(0.1 * 3, 0.1)), "0.3");          // a step of 0.1
  EXPECT_EQ(shortest(slider_value(1234.5678, 100)), "1200");
  EXPECT_EQ(shortest(slider_value(-0.0123456, 1e-4)), "-0.0123");
  EXPECT_EQ(shortest(slider_value(2.5e-7, 1e-9)), "2.5e-07");
  // Never farther than half the resolution; the value itself without one.
  for (double v : {0.123456789, 98.7654321, -3.33333333, 1e-5 * 7.77}) {
    for (double r : {1e-6, 1e-3, 0.05, 0.7}) EXPECT_LE(std::abs(slider_value(v, r) - v), r / 2) << v << " " << r;
  }
  EXPECT_EQ(slider_value(6.13636, 0), 6.13636);
  EXPECT_EQ(slider_value(6.13636, std::nan("")), 6.13636);
}

TEST(CodeEditorPlaces, AnEditEndsAfterTheCommonPrefixAndBeforeTheCommonSuffix) {
  EXPECT_EQ(changed_until("abcXdef", "abcdef"), 3u);    // a deletion: where it was
  EXPECT_EQ(changed_until("abcdef", "abcXYdef"), 5u);   // an insertion: after it
  EXPECT_EQ(changed_until("aaa", "aaaa"), 4u);          // repeats: the end of the longest prefix
  EXPECT_EQ(changed_until("x", "x"), 1u);
  uint32_t line = 0, column = 0;
  line_column("ab\ncd\n", 6, 4, &line, &column);
  EXPECT_EQ(line, 2u);
  EXPECT_EQ(column, 2u);
}

TEST(DefineControls, TypedNumbersAreExact) {
  EXPECT_EQ(*parse_exact("0.1"), 0.1);
  EXPECT_EQ(*parse_exact(" 1e-3 "), 1e-3);
  EXPECT_EQ(*parse_exact("0.30000000000000004"), 0.1 + 0.2);
  EXPECT_FALSE(parse_exact("1.5x"));
  EXPECT_FALSE(parse_exact("inf"));
  EXPECT_FALSE(parse_exact(""));
  EXPECT_EQ(shortest(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(shortest(3), "3");
}

TEST(UndoHistory, WholeStatesOneStepEach) {
  UndoHistory h(DocState{"a", {}, {}, {}});
  EXPECT_FALSE(h.record(DocState{"a", {}, {}, {}})) << "an equal snapshot is no step";
  EXPECT_TRUE(h.record(DocState{"ab", {}, {}, {}}));
  EXPECT_TRUE(h.record(DocState{"ab", {{"N", 4}}, {}, {}}));
  EXPECT_EQ(h.undo().defines.size(), 0u);
  EXPECT_EQ(h.undo().text, "a");
  EXPECT_FALSE(h.can_undo());
  EXPECT_EQ(h.redo().text, "ab");
  EXPECT_TRUE(h.record(DocState{"abc", {}, {}, {}}));
  EXPECT_FALSE(h.can_redo()) << "a new step drops the redo tail";
  EXPECT_EQ(h.size(), 3u);
}

TEST(OrbitCamera, RoundTripsACameraAndOrbitsWithoutRoll) {
  Camera c;
  c.eye = {3, 4, 5};
  c.target = {0, 1, 0};
  OrbitCamera o = OrbitCamera::from(c);
  EXPECT_NEAR(o.eye().x, 3, 1e-12);
  EXPECT_NEAR(o.eye().y, 4, 1e-12);
  EXPECT_NEAR(o.eye().z, 5, 1e-12);
  const double d = o.distance;
  o.orbit(100, 50);
  EXPECT_NEAR(glm::length(o.eye() - o.target), d, 1e-9) << "orbiting keeps the distance";
  o.zoom(1);
  EXPECT_NEAR(o.distance, d * 0.85, 1e-9);
  o.orbit(0, 10000);
  EXPECT_LE(o.pitch_deg, 89);
}

const char* const kBinaryTree =
    "#define N 4\n"
    "angle: 30\n"
    "derivation length: N\n"
    "axiom: A\n"
    "productions:\n"
    "A -> F[+A][-A]\n";

GrowRequest request(const std::string& text, std::map<std::string, double> defines = {}) {
  GrowRequest r;
  r.text = text;
  r.file = "tree.lsys";
  r.plants.push_back(PlantVariant{std::move(defines), {}, {}});
  return r;
}

std::optional<GrowOutcome> wait_result(GrowWorker& w) {
  EXPECT_TRUE(w.wait_idle(30));
  return w.poll();
}

TEST(GrowWorker, GrowsAPlantOffTheCallingThread) {
  GrowWorker w;
  w.submit(request(kBinaryTree));
  auto out = wait_result(w);
  ASSERT_TRUE(out);
  ASSERT_FALSE(out->error);
  ASSERT_EQ(out->skeletons.size(), 1u);
  EXPECT_EQ(out->steps, 4);
  EXPECT_EQ(out->shown_step, 4);
  EXPECT_EQ(out->segments, 15u) << "1 + 2 + 4 + 8 segments";
  EXPECT_EQ(out->skeletons[0].source.grammar, "tree.lsys");
}

TEST(GrowWorker, AParseErrorIsTheCliDiagnostic) {
  GrowWorker w;
  w.submit(request("axiom: A\nproductions:\nA -> F[+A\n"));
  auto out = wait_result(w);
  ASSERT_TRUE(out && out->error);
  EXPECT_EQ(out->error->file, "tree.lsys");
  EXPECT_EQ(out->error->loc.line, 3u);
  EXPECT_NE(out->error->format().find("tree.lsys:3:"), std::string::npos) << out->error->format();
}

TEST(GrowWorker, SixtyRapidEditsKeepOnlyTheLast) {
  GrowWorker w;
  // A derivation long enough that edits arrive while it runs.
  const std::string heavy = "#define N 18\nderivation length: N\naxiom: A\nproductions:\nA -> F[+A][-A]\n";
  uint64_t last = 0;
  for (int i = 0; i < 60; ++i) {
    last = w.submit(request(heavy, {{"N", 16.0 + (i % 3)}}));
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  last = w.submit(request(heavy, {{"N", 10}}));
  auto out = wait_result(w);
  ASSERT_TRUE(out);
  ASSERT_FALSE(out->error);
  EXPECT_EQ(out->generation, last);
  EXPECT_EQ(out->steps, 10);
  EXPECT_EQ(out->segments, 1023u);
  const WorkerCounts c = w.counts();
  EXPECT_EQ(c.submitted, 61u);
  EXPECT_LE(c.started, c.submitted) << "a queued request replaced before it starts never runs";
  EXPECT_EQ(c.started, c.cancelled + c.finished);
  EXPECT_GE(c.finished, 1u);
  EXPECT_EQ(c.dropped, c.finished - 1) << "every finished result but the last was dropped, never shown";
  EXPECT_FALSE(w.poll()) << "one result, once";
}

TEST(GrowWorker, CancelsBetweenDerivationSteps) {
  GrowWorker w;
  // ~2^24 modules at the last steps: seconds of work, cancelled after a few ms.
  w.submit(request("derivation length: 23\naxiom: A\nproductions:\nA -> AB\nB -> A\n"));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto t0 = std::chrono::steady_clock::now();
  w.cancel();
  EXPECT_TRUE(w.wait_idle(30));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  EXPECT_FALSE(w.poll());
}

TEST(GrowWorker, StepsComeFromTheCache) {
  GrowWorker w;
  w.submit(request(kBinaryTree));
  ASSERT_TRUE(wait_result(w));
  GrowRequest r = request(kBinaryTree);
  r.show_step = 2;
  w.submit(r);
  auto out = wait_result(w);
  ASSERT_TRUE(out);
  EXPECT_TRUE(out->from_cache);
  EXPECT_EQ(out->shown_step, 2);
  EXPECT_EQ(out->segments, 3u);
  r.show_step = 0;
  w.submit(r);
  out = wait_result(w);
  ASSERT_TRUE(out);
  EXPECT_TRUE(out->from_cache);
  EXPECT_EQ(out->segments, 0u) << "the axiom A draws nothing";
}

}  // namespace
}  // namespace sylva::studio
