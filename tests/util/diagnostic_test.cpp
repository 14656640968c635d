// Tests for core/util/diagnostic.h: the one located error type, its text, its notes, and
// the Expected/Status results that carry it.
#include "core/util/diagnostic.h"

#include <gtest/gtest.h>

#include <string>

namespace sylva {
namespace {

TEST(Diagnostic, ALocatedErrorWithSourceShowsTheLineAndACaret) {
  Diagnostic d = diagnostic_at("g.lsys", {2, 8}, "unknown function 'foo'");
  d.source_line = "A -> F(foo(2))";
  EXPECT_EQ(d.format(), "g.lsys:2:8: error: unknown function 'foo'\nA -> F(foo(2))\n       ^\n");
}

TEST(Diagnostic, WithoutSourceLineThePlaceIsTheWholeMessage) {
  EXPECT_EQ(diagnostic_at("s.scene.json", {3, 7}, "bad").format(), "s.scene.json:3:7: error: bad\n");
  EXPECT_EQ(diagnostic_at("a.json", {3, 0}, "bad").format(), "a.json:3: error: bad\n");
  EXPECT_EQ(file_diagnostic("a.json", "bad").format(), "a.json: error: bad\n");
  EXPECT_EQ(file_diagnostic("", "bad").format(), "error: bad\n");
  EXPECT_EQ(diagnostic_at("", {3, 7}, "bad").format(), "3:7: error: bad\n");
}

TEST(Diagnostic, AnEmptySourceLineStillGetsItsCaret) {
  Diagnostic d = diagnostic_at("g.lsys", {4, 1}, "unexpected end of file");
  d.source_line = "";
  EXPECT_EQ(d.format(), "g.lsys:4:1: error: unexpected end of file\n\n^\n");
}

TEST(Diagnostic, NotesFollowTheErrorEachAtItsOwnPlace) {
  Diagnostic grammar = diagnostic_at("bad.lsys", {2, 8}, "unknown function 'foo'");
  grammar.source_line = "A -> F(foo(2))";
  const Diagnostic d = std::move(grammar).with_note(
      diagnostic_at("forest.scene.json", {4, 16}, "plants[1].grammar names this grammar"));
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_EQ(d.notes[0].file, "forest.scene.json");
  EXPECT_EQ(d.notes[0].loc, (SourceLoc{4, 16}));
  EXPECT_EQ(d.format(),
            "bad.lsys:2:8: error: unknown function 'foo'\n"
            "A -> F(foo(2))\n"
            "       ^\n"
            "forest.scene.json:4:16: note: plants[1].grammar names this grammar\n");
}

TEST(Diagnostic, ControlBytesAreEchoedAsQuestionMarksKeepingTheCaretAligned) {
  Diagnostic d = diagnostic_at("g", {1, 4}, "m");
  d.source_line = "a\x01\tb";
  EXPECT_EQ(d.format(), "g:1:4: error: m\na? b\n   ^\n");  // tab: one blank, caret under b
}

TEST(Diagnostic, FileDiagnosticsCarryTheSystemErrorNumber) {
  const Diagnostic d = file_diagnostic("x", "cannot open", 2);
  EXPECT_EQ(d.error_number, 2);
  EXPECT_FALSE(d.cancelled);
}

TEST(Diagnostic, CancellationIsNotAFailure) {
  const Diagnostic d = cancelled_diagnostic();
  EXPECT_TRUE(d.cancelled);
  EXPECT_EQ(d.message, "cancelled");
  Expected<int> e = d;
  EXPECT_FALSE(e.ok());
  EXPECT_TRUE(e.cancelled());
  Expected<int> failed = file_diagnostic("x", "broken");
  EXPECT_FALSE(failed.cancelled());
}

TEST(Expected, HoldsAValueOrADiagnostic) {
  Expected<std::string> good = std::string("plant");
  ASSERT_TRUE(good.ok());
  EXPECT_TRUE(static_cast<bool>(good));
  EXPECT_EQ(*good, "plant");
  EXPECT_EQ(good->size(), 5u);
  Expected<std::string> bad = file_diagnostic("f", "no");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "no");
}

TEST(Status, IsSuccessOrADiagnostic) {
  const Status fine;
  EXPECT_TRUE(fine.ok());
  EXPECT_FALSE(fine.cancelled());
  const Status broken = file_diagnostic("f", "no");
  ASSERT_FALSE(broken.ok());
  EXPECT_FALSE(static_cast<bool>(broken));
  EXPECT_EQ(broken.error().format(), "f: error: no\n");
  const Status stopped = cancelled_diagnostic();
  EXPECT_TRUE(stopped.cancelled());
}

}  // namespace
}  // namespace sylva
