// Grammar text: directives, defines and overrides, module names, comments, continuations,
// production forms and located syntax errors.
#include "tests/lsystem/lsystem_test_util.h"

namespace sylva::lsys {
namespace {

using testing::derive_text;
using testing::parse_error;
using testing::parse_ok;

TEST(Directives, EveryHeaderDirectiveIsRead) {
  Grammar g = parse_ok(
      "angle: 22.5\nwidth: 0.1\nwidth decrement: 0.5\nstep: 2\ntropism: 0 -1 0 0.2\n"
      "seed: 42\nderivation length: 7\nmaximum depth: 3\naxiom: F\n");
  EXPECT_EQ(g.turtle.angle_deg, 22.5);
  EXPECT_EQ(g.turtle.width, 0.1);
  EXPECT_EQ(g.turtle.width_decrement, 0.5);
  EXPECT_EQ(g.turtle.step, 2);
  EXPECT_TRUE(g.turtle.has_tropism);
  EXPECT_EQ(g.turtle.tropism[1], -1);
  EXPECT_EQ(g.turtle.tropism_e, 0.2);
  EXPECT_EQ(g.seed, 42u);
  EXPECT_EQ(g.steps, 7);
  EXPECT_EQ(g.max_depth, 3);
}

TEST(Directives, DefaultsAreThoseOfGrammarMd) {
  Grammar g = parse_ok("axiom: F\n");
  EXPECT_EQ(g.turtle.angle_deg, 90);
  EXPECT_EQ(g.turtle.width, 0.05);
  EXPECT_EQ(g.turtle.width_decrement, 0.7);
  EXPECT_EQ(g.turtle.step, 1);
  EXPECT_FALSE(g.turtle.has_tropism);
  EXPECT_EQ(g.seed, 1u);
  EXPECT_EQ(g.steps, 1);
  EXPECT_EQ(g.max_depth, 16);
}

TEST(Directives, AliasesAndExpressionsOverDefinesAreAccepted) {
  Grammar g = parse_ok("#define N 4\n#define D 30\nsteps: N+1\nangle: D/2\ntropism: 0, -1, 0, D/100\n\xCF\x89: F\n");
  EXPECT_EQ(g.steps, 5);
  EXPECT_EQ(g.turtle.angle_deg, 15);
  EXPECT_EQ(g.turtle.tropism_e, 0.3);
  EXPECT_EQ(g.axiom.size(), 1u);
}

TEST(Directives, ASeedIsA64BitIntegerReadExactly) {
  Grammar g = parse_ok("seed: 18446744073709551615\naxiom: F\n");
  EXPECT_EQ(g.seed, 18446744073709551615ull);
  EXPECT_NE(parse_error("seed: 18446744073709551616\naxiom: F\n").message.find("out of range"), std::string::npos);
  EXPECT_NE(parse_error("seed: -1\naxiom: F\n").message.find("non-negative integer"), std::string::npos);
}

TEST(Defines, OverridesReplaceTheValueAndFlowIntoLaterDefines) {
  ParseOptions o;
  o.define_overrides["N"] = 3;
  Grammar g = parse_ok("#define N 1\n#define M N*2\naxiom: X(N,M)\n", o);
  EXPECT_EQ(g.axiom.params[0], 3);
  EXPECT_EQ(g.axiom.params[1], 6);
  EXPECT_TRUE(g.defines[0].overridden);
  EXPECT_FALSE(g.defines[1].overridden);
}

TEST(Defines, AnOverrideForAnUndefinedNameIsAnError) {
  ParseOptions o;
  o.define_overrides["NOPE"] = 3;
  Diagnostic d = parse_error("#define N 1\naxiom: F\n", o);
  EXPECT_EQ(d.loc.line, 0u);
  EXPECT_NE(d.message.find("-D NOPE"), std::string::npos);
}

TEST(Defines, DuplicatesAndBuiltinNamesAreRejected) {
  Diagnostic d = parse_error("#define N 1\n#define N 2\naxiom: F\n");
  EXPECT_EQ(d.loc.line, 2u);
  EXPECT_NE(d.message.find("defined twice"), std::string::npos);
  EXPECT_NE(parse_error("#define sin 1\naxiom: F\n").message.find("built-in"), std::string::npos);
  EXPECT_NE(parse_error("#define\naxiom: F\n").message.find("needs a name"), std::string::npos);
}

TEST(ModuleNames, DeclaredMultiCharacterNamesAreTokenisedLongestFirst) {
  Grammar g = parse_ok("module: Apex Internode Ap\naxiom: ApexInternodeApA\n");
  ASSERT_EQ(g.axiom.size(), 4u);
  EXPECT_EQ(g.symbols.name(g.axiom.modules[0].symbol), "Apex");
  EXPECT_EQ(g.symbols.name(g.axiom.modules[1].symbol), "Internode");
  EXPECT_EQ(g.symbols.name(g.axiom.modules[2].symbol), "Ap");
  EXPECT_EQ(g.symbols.name(g.axiom.modules[3].symbol), "A");
}

TEST(ModuleNames, UndeclaredNamesAreOneCharacterEachIncludingUtf8) {
  Grammar g = parse_ok("axiom: AB\xCE\xB1\n");
  ASSERT_EQ(g.axiom.size(), 3u);
  EXPECT_EQ(g.symbols.name(g.axiom.modules[2].symbol), "\xCE\xB1");
}

TEST(ModuleNames, MultiCharacterModulesRewriteLikeAnyOther) {
  EXPECT_EQ(derive_text("module: Apex Leaf\naxiom: Apex\nApex -> F[Leaf]Apex\n", DeriveOptions{2, {}, 1000, {}}),
            "F[Leaf]F[Leaf]Apex");
}

TEST(Comments, HashLinesAndBlockCommentsAreIgnoredAndDoubleSlashIsTwoRolls) {
  Grammar g = parse_ok("# a comment\n  # indented comment\naxiom: F/* inline */F // \n/* multi\nline */\n");
  ASSERT_EQ(g.axiom.size(), 4u);
  EXPECT_EQ(g.axiom.modules[2].symbol, kSymRollRight);
  EXPECT_EQ(g.axiom.modules[3].symbol, kSymRollRight);
}

TEST(Comments, AnUnterminatedBlockCommentIsLocatedAtItsStart) {
  Diagnostic d = parse_error("axiom: F\n  /* never closed\nF -> FF\n");
  EXPECT_EQ(d.loc.line, 2u);
  EXPECT_EQ(d.loc.column, 3u);
  EXPECT_NE(d.message.find("unterminated comment"), std::string::npos);
}

TEST(Continuations, ABackslashAtLineEndJoinsTheNextLineAndPlacesStayTrue) {
  EXPECT_EQ(derive_text("axiom: A\nA -> F[+F]\\\n  F[-F]F\n"), "F[+F]F[-F]F");
  // An error on the continued line is reported at its physical line and column.
  Diagnostic d = parse_error("axiom: A\nA -> F[+F]\\\n  F(1+)\n");
  EXPECT_EQ(d.loc.line, 3u);
  EXPECT_EQ(d.loc.column, 7u);
}

TEST(Productions, AllFormsParse) {
  Grammar g = parse_ok(
      "axiom: A\n"
      "p1: A -> B\n"
      "B --> C\n"
      "L < C > R -> D\n"
      "C(x) : x > 1 -> E\n"
      "D : * -> F : 0.5\n"
      "- -> +\n"
      "+ --> -\n");
  ASSERT_EQ(g.productions.size(), 7u);
  EXPECT_EQ(g.productions[0].label, "p1");
  EXPECT_EQ(g.productions[2].left_context.size(), 1u);
  EXPECT_EQ(g.productions[2].right_context.size(), 1u);
  EXPECT_NE(g.productions[3].condition.kind, Expr::Kind::kNone);
  EXPECT_EQ(g.productions[4].condition.kind, Expr::Kind::kNone);  // '*' is always
  EXPECT_NE(g.productions[4].probability.kind, Expr::Kind::kNone);
  EXPECT_EQ(g.productions[5].predecessor.symbol, kSymTurnRight);
  EXPECT_EQ(g.productions[6].predecessor.symbol, kSymTurnLeft);
  EXPECT_EQ(g.productions[6].successor.prebuilt.modules[0].symbol, kSymTurnRight);
}

TEST(Productions, AnEmptySuccessorErasesTheModule) {
  EXPECT_EQ(derive_text("axiom: ABA\nB ->\n"), "AA");
}

TEST(Productions, SectionsSeparateRewritingFromInterpretation) {
  Grammar g = parse_ok("axiom: A\nproductions:\nA -> AB\nhomomorphism:\nB -> F\ninterpretation:\nA -> f\n");
  EXPECT_EQ(g.productions.size(), 1u);
  EXPECT_EQ(g.homomorphism.size(), 2u);
}

TEST(SyntaxErrors, AreLocatedWithLineAndColumn) {
  struct Case {
    std::string text;
    uint32_t line, column;
    const char* message;
  } cases[] = {
      {"axiom: F[F\n", 1, 9, "'[' is never closed"},
      {"axiom: F]F\n", 1, 9, "without matching '['"},
      {"axiom: F\nA -> B[C\n", 2, 7, "never closed"},
      {"colour: 3\naxiom: F\n", 1, 1, "unknown directive 'colour'"},
      {"", 1, 1, "no axiom"},
      {"# only a comment\n", 1, 1, "no axiom"},
      {"axiom: F\naxiom: G\n", 2, 1, "axiom is given twice"},
      {"axiom: F(1\n", 1, 9, "never closed"},
      {"axiom: F)\n", 1, 9, "unexpected ')'"},
      {"axiom: F\n -> B\n", 2, 2, "expected a predecessor"},
      {"axiom: F\nA -> B :\n", 2, 9, "expected a probability"},
      {"axiom: F\nA -> B : -1\n", 2, 10, "must not be negative"},
      {"axiom: F\nA : -> B\n", 2, 5, "expected a condition"},
      {"axiom: F\nq1: A -> B\n", 2, 1, "label 'q1'"},
      {"axiom: F\n < A -> B\n", 2, 2, "expected a left context"},
      {"axiom: F\nAB -> C\n", 2, 1, "one module"},
      {"axiom: F\nA(x, x) -> B\n", 2, 6, "declared twice"},
      {"axiom: F\nA -> F(1+)\n", 2, 10, "expected an expression"},
      {"angle: x\naxiom: F\n", 1, 8, "unknown name 'x'"},
      {"derivation length: -1\naxiom: F\n", 1, 20, "non-negative integer"},
      {"module: 1abc\naxiom: F\n", 1, 9, "must not start with a digit"},
      {"axiom: F\nA -> B\nthis is nonsense\n", 3, 1, "expected a production"},
      {"axiom: F\xFF\n", 1, 9, "invalid UTF-8"},
      {std::string("axiom: F\0G\n", 11), 1, 9, "NUL"},
      {"tropism: 0 1 0\naxiom: F\n", 1, 10, "four values"},
      {"axiom: F\nA > ]B -> C\nB -> ]\n", 3, 6, "without matching"},
      {"axiom: F\n[ -> F\n", 2, 1, "cannot be rewritten"},
      {"axiom: F\nA x -> B\n", 2, 1, "one module"},
      // A BOM anywhere but first, and CR-only line endings: errors at the character.
      {"axiom: F\nF -> F\xEF\xBB\xBF[+F]F\n", 2, 7, "byte order mark (U+FEFF) inside the text"},
      {"\xEF\xBB\xBF\xEF\xBB\xBF" "axiom: F\n", 1, 4, "byte order mark"},
      {"derivation length: 2\raxiom: F\rF -> FF\r", 1, 21, "CR-only (classic Mac) line endings"},
      {"axiom: F\r\nF -> F\rF\r\n", 2, 7, "carriage return without a line feed"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    Diagnostic d = parse_error(c.text);
    EXPECT_EQ(d.loc.line, c.line) << d.format();
    EXPECT_EQ(d.loc.column, c.column) << d.format();
    EXPECT_NE(d.message.find(c.message), std::string::npos) << d.format();
  }
}

TEST(SyntaxErrors, TheFormattedMessageShowsTheSourceLineAndACaret) {
  Diagnostic d = parse_error("axiom: F\nA -> F(foo(2))\n");
  EXPECT_EQ(d.format(), "test.lsys:2:8: error: unknown function 'foo'\nA -> F(foo(2))\n       ^\n");
}

// The caret line of a CR-only file is its first line, not the whole file.
TEST(SyntaxErrors, ACrOnlyFileShowsItsFirstLineWithTheCaretAtTheCarriageReturn) {
  Diagnostic d = parse_error("axiom: F\rF -> FF\r");
  EXPECT_EQ(d.format(),
            "test.lsys:1:9: error: a carriage return without a line feed after it: CR-only (classic Mac) line "
            "endings are not read; save the file with LF or CRLF line endings\naxiom: F\n        ^\n");
}

// A BOM as the first bytes is skipped, as before; CRLF line endings are read.
TEST(SyntaxErrors, ALeadingBomAndCrlfLineEndingsAreRead) {
  Grammar g = parse_ok("\xEF\xBB\xBF" "axiom: F\r\nF -> FF\r\n");
  EXPECT_EQ(g.axiom.size(), 1u);
  EXPECT_EQ(g.productions.size(), 1u);
}

TEST(SyntaxErrors, AMillionNestedBracketsParseWithoutRecursion) {
  std::string axiom(1000000, '[');
  axiom += "F";
  axiom += std::string(1000000, ']');
  Grammar g = parse_ok("axiom: " + axiom + "\n");
  EXPECT_EQ(g.axiom.size(), 2000001u);
  Diagnostic d = parse_error("axiom: " + std::string(1000000, '[') + "F\n");
  EXPECT_NE(d.message.find("never closed"), std::string::npos);
}

}  // namespace
}  // namespace sylva::lsys
