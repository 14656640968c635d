// Work bounds (docs/limits.md "Work"): declaring names, tokenising and printing with many
// declared names, context matching across branches and interpretation depth stay linear
// in their input. Each test counts the work with the counters the code exposes, so it
// fails on a quadratic walk however fast the machine is.
#include <string>

#include "tests/lsystem/lsystem_test_util.h"

namespace sylva::lsys {
namespace {

using testing::parse_error;
using testing::parse_ok;

// `count` declared names N0, N1, ... on `module:` lines of 100 names each.
std::string declarations(int count) {
  std::string text;
  for (int i = 0; i < count; ++i) {
    text += (i % 100 == 0 ? "\nmodule:" : "") + std::string(" N") + std::to_string(i);
  }
  return text + "\n";
}

TEST(Work, DeclaringTensOfThousandsOfNamesCostsTheirLength) {
  const std::string text = declarations(30000) + "axiom: N29999 N7 N\nN7 -> N12345\n";
  symbol_work() = {};
  Grammar g = parse_ok(text);
  // One trie step per declared byte, plus the axiom's and production's names: a scan of
  // the declared names at each declaration or each module would be 30,000 times more.
  EXPECT_LE(symbol_work().trie_steps, 2 * text.size());
  auto w = derive(g);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(print_word(*w, g.symbols), "N29999N12345N");
}

TEST(Work, PrintingAWordWithManyDeclaredNamesCostsItsLength) {
  // "N" is a prefix of every declared name, so each of its modules needs the look-ahead.
  Grammar g = parse_ok(declarations(20000) + "axiom: N\n");
  Word w;
  for (int i = 0; i < 100000; ++i) w.modules.push_back(Module{g.symbols.intern(i % 2 ? "N" : "N1"), 0, 0});
  symbol_work() = {};
  const std::string printed = print_word(w, g.symbols);
  const uint64_t names_bytes = 20000 * 6;
  EXPECT_LE(symbol_work().trie_steps, 2 * names_bytes + 8 * w.size());
  auto back = parse_word(printed, g);
  ASSERT_TRUE(back.ok()) << back.error().format();
  ASSERT_EQ(back->size(), w.size());
  for (size_t i = 0; i < w.size(); ++i) ASSERT_EQ(back->modules[i].symbol, w.modules[i].symbol) << i;
}

TEST(Work, PrintingSeparatesANameFromTheStartOfAMuchLongerDeclaredName) {
  // X followed by 70 modules Y would read back as the declared 71-byte name: the printer
  // looks ahead as far as a declared name continues, not a fixed distance.
  const std::string longer = "X" + std::string(70, 'Y');
  Grammar g = parse_ok("module: " + longer + "\naxiom: X\n");
  auto w = parse_word("X " + std::string(70, 'Y'), g);
  ASSERT_TRUE(w.ok());
  ASSERT_EQ(w->size(), 71u);
  const std::string printed = print_word(*w, g.symbols);
  EXPECT_EQ(printed, "X " + std::string(70, 'Y'));
  auto back = parse_word(printed, g);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->size(), 71u);
}

TEST(Work, RightContextAcrossABranchEndCostsThePatternNotTheBranch) {
  // Every A looks past the rest of its branch to the B after it: one step each for the
  // pattern's ']' and B, however long the branch.
  const int n = 20000;
  Grammar g = parse_ok("axiom: [" + std::string(n, 'A') + "]B\nA > ]B -> C\n");
  DeriveStats stats;
  auto w = derive(g, {}, &stats);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(print_word(*w, g.symbols), "[" + std::string(n, 'C') + "]B");
  EXPECT_LE(stats.context_steps, 2u * n);
}

TEST(Work, ContextPassesOverIgnoredRunsAndSiblingBranchesInOneStep) {
  const int n = 20000;
  // Each B's left context is X below all the sibling branches before it.
  std::string siblings;
  for (int i = 0; i < n; ++i) siblings += "[B]";
  Grammar left = parse_ok("axiom: X" + siblings + "\nX < B -> C\n");
  DeriveStats stats;
  auto w = derive(left, {}, &stats);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(print_word(*w, left.symbols).substr(0, 7), "X[C][C]");
  EXPECT_LE(stats.context_steps, 1u * n);
  // Every F looks right past the run of ignored + to the G at its end.
  std::string run;
  for (int i = 0; i < n; ++i) run += "F+";
  Grammar right = parse_ok("ignore: +\naxiom: " + run + "G\nF > G -> H\n");
  stats = {};
  w = derive(right, {}, &stats);
  ASSERT_TRUE(w.ok());
  const std::string printed = print_word(*w, right.symbols);
  EXPECT_EQ(printed.substr(printed.size() - 3), "H+G");
  EXPECT_EQ(printed.substr(0, 2), "F+");
  EXPECT_LE(stats.context_steps, 1u * n);
}

TEST(Work, InterpretationCopiesAModuleWithoutAProductionOnce) {
  // 16 passes of A -> A over a word of 20,000 F: the F are written once, not 16 times
  // (pass by pass, the work would be 16 x 20,001).
  const int n = 20000;
  Grammar g = parse_ok("axiom: " + std::string(n, 'F') + "A\nhomomorphism:\nA -> A\n");
  auto w = derive(g);
  ASSERT_TRUE(w.ok());
  InterpretStats stats;
  auto t = interpret(g, *w, {}, &stats);
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(print_word(*t, g.symbols), std::string(n, 'F') + "A");
  EXPECT_EQ(stats.depth, 16);
  EXPECT_EQ(stats.still_expandable, 1u);
  EXPECT_LE(stats.work, n + 4u * 16);
}

TEST(Work, InterpretationMatchesPassByPassWithContext) {
  // The same homomorphism with and without a (trivially true) context gives one word:
  // depth first and pass by pass agree, random streams included.
  const char* body =
      "seed: 7\naxiom: [FAB]FA\nhomomorphism:\nmaximum depth: 5\n"
      "A -> F(uniform(1,2))[+A]A : 0.5\nA -> B : 0.5\nB -> F(rand())\n";
  Grammar plain = parse_ok(body);
  Grammar context = parse_ok(std::string(body) + "Q < Z -> Z\n");
  auto wp = derive(plain), wc = derive(context);
  ASSERT_TRUE(wp.ok() && wc.ok());
  InterpretStats sp, sc;
  auto tp = interpret(plain, *wp, {}, &sp), tc = interpret(context, *wc, {}, &sc);
  ASSERT_TRUE(tp.ok() && tc.ok());
  EXPECT_EQ(print_word(*tp, plain.symbols), print_word(*tc, context.symbols));
  EXPECT_GT(tp->size(), 10u);
  EXPECT_EQ(sp.depth, sc.depth);
  EXPECT_EQ(sp.still_expandable, sc.still_expandable);
}

TEST(Work, AnInterpretationPastItsBudgetFailsAtItsProduction) {
  // A(n) doubles n times and then vanishes: a tiny result after 2^31 rewrites.
  Grammar g = parse_ok("axiom: A(30)\nhomomorphism:\nmaximum depth: 40\nA(n) : n > 0 -> A(n-1)A(n-1)\n"
                       "A(n) : n <= 0 ->\n");
  auto w = derive(g);
  ASSERT_TRUE(w.ok());
  DeriveOptions o;
  o.max_modules = 1000;
  auto t = interpret(g, *w, o);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().loc.line, 4u);
  EXPECT_NE(t.error().message.find("budget of 16000 modules written (16 x --max-modules)"), std::string::npos)
      << t.error().message;
}

// Issue 32, item 11: readers that cost far more than their input.
TEST(Work, TwoHundredThousandLineContinuationsAreJoinedInLinearTime) {
  std::string text = "axiom: F\nF -> F";
  for (int i = 0; i < 200000; ++i) text += "\\\n F";
  text += "\n";
  parse_work() = {};
  Grammar g = parse_ok(text);
  // Geometric growth: each byte is copied a few times at most. Reserving exactly what each
  // physical line added copied the joined line once per line: ~6·10^11 bytes here.
  EXPECT_LE(parse_work().line_bytes_copied, 2 * text.size());
  EXPECT_EQ(parse_work().logical_lines, 2u);
  DeriveOptions one;
  one.steps = 1;
  auto w = derive(g, one);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(w->size(), 200001u);
}

TEST(Work, FourHundredThousandDefinesAreCheckedForRepeatsByHash) {
  std::string text;
  for (int i = 0; i < 400000; ++i) text += "#define D" + std::to_string(i) + " " + std::to_string(i) + "\n";
  text += "axiom: A(D399999)\n";
  parse_work() = {};
  Grammar g = parse_ok(text);
  EXPECT_EQ(parse_work().define_compares, 0u);  // each new name against every earlier one: 8·10^10
  EXPECT_EQ(g.defines.size(), 400000u);
  // A repeat is still found, and says where the first one is.
  const Diagnostic twice = parse_error("#define A 1\n#define B 2\n#define A 3\naxiom: F\n");
  EXPECT_NE(twice.message.find("'A' is defined twice (first at line 1)"), std::string::npos) << twice.message;
  EXPECT_EQ(twice.loc.line, 3u);
}

TEST(Work, BlankLinesKeepNothing) {
  const std::string text = std::string(1000000, '\n') + "   \n\t\naxiom: F\n" + std::string(1000, '\n');
  parse_work() = {};
  Grammar g = parse_ok(text);
  EXPECT_EQ(parse_work().logical_lines, 1u);  // a logical line per blank line: ~100 bytes each
  const Diagnostic e = parse_error(std::string(100000, '\n') + "axiom: F\nF -> G(\n");
  EXPECT_EQ(e.loc.line, 100002u);  // places still count every line
}

TEST(Work, AnErrorInAHugeLineQuotesOnlyItsNeighbourhood) {
  // The axiom's 600,001st byte is the bad one: the diagnostic keeps 4 KiB around it, not
  // the 1 MB line (a 1 GiB line of NULs had been copied twice more).
  std::string line = "axiom: " + std::string(600000, 'F') + ")" + std::string(400000, 'F');
  const Diagnostic e = parse_error(line + "\n");
  ASSERT_TRUE(e.source_line);
  EXPECT_LE(e.source_line->size(), kMaxSourceLineBytes);
  EXPECT_EQ(e.loc.column, 600008u) << e.message;
  EXPECT_EQ((*e.source_line)[e.loc.column - 1 - e.source_offset], ')');
  // The excerpt shows the ')' with the caret under it.
  const std::string text = e.format();
  const size_t excerpt = text.find('\n') + 1, caret_line = text.find('\n', excerpt) + 1;
  const size_t caret = text.find('^', caret_line) - caret_line;
  EXPECT_EQ(text[excerpt + caret], ')') << text.substr(0, 600);
}

}  // namespace
}  // namespace sylva::lsys
