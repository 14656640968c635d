// Derivation: parallel rewriting, identity, bracket-aware context (ABOP 1.8), ignore
// lists, stochastic choice, determinism, cut, homomorphism, limits.
#include <atomic>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "tests/lsystem/lsystem_test_util.h"

namespace sylva::lsys {
namespace {

using testing::derive_text;
using testing::parse_ok;
using testing::steps;

TEST(Derive, RewritesInParallelAndCopiesModulesWithoutRules) {
  EXPECT_EQ(derive_text("axiom: F\nF -> F[+F]F\n", steps(2)), "F[+F]F[+F[+F]F]F[+F]F");
  EXPECT_EQ(derive_text("axiom: AB\nA -> B\nB -> A\n", steps(1)), "BA");  // parallel, not sequential
  EXPECT_EQ(derive_text("axiom: XYZ\nY -> YY\n", steps(3)), "XYYYYYYYYZ");
}

TEST(Derive, StepsDefaultToTheGrammarAndZeroStepsGiveTheAxiom) {
  EXPECT_EQ(derive_text("derivation length: 2\naxiom: A\nA -> AB\n"), "ABB");
  EXPECT_EQ(derive_text("derivation length: 2\naxiom: A\nA -> AB\n", steps(0)), "A");
}

TEST(Derive, ParametricProductionsBindFormalsAndTestConditionsInFileOrder) {
  const char* g =
      "axiom: A(0)\n"
      "A(t) : t < 2 -> A(t+1)\n"
      "A(t) : t >= 2 -> B(t*10)\n";
  EXPECT_EQ(derive_text(g, steps(2)), "A(2)");
  EXPECT_EQ(derive_text(g, steps(3)), "B(20)");
  // The first matching production wins.
  EXPECT_EQ(derive_text("axiom: A(1)\nA(x) : x > 0 -> B\nA(x) : x > 0 -> C\n"), "B");
}

TEST(Derive, ParameterCountMismatchNamesTheProductionAndModule) {
  auto g = parse_ok("axiom: A(1)\np1: A(x,y) -> B\n");
  auto w = derive(g, steps(1));
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().loc.line, 2u);
  EXPECT_NE(w.error().message.find("parameter count"), std::string::npos);
  EXPECT_NE(w.error().message.find("A(1)"), std::string::npos);
  // A production of another arity for the same symbol makes it a legitimate identity.
  EXPECT_EQ(derive_text("axiom: A(1)A\nA -> B\n"), "<error: parameter count: module has 1 parameter but the "
                                                  "production expects 0, in production 'A -> B' at 2:1 rewriting "
                                                  "module A(1) at step 1>");
  EXPECT_EQ(derive_text("axiom: A(1)A\nA -> B\nA(x) : x > 5 -> C\n"), "A(1)B");
}

TEST(Context, LeftContextSkipsCompletedBranchesAndClimbsOutOfTheCurrentOne) {
  // B's left neighbour on its path is A: the branch [C] before B is completed, skip it.
  EXPECT_EQ(derive_text("axiom: A[C]B\nA < B -> X\n"), "A[C]X");
  // Inside a branch, the left context climbs out through '[' to the parent: A.
  EXPECT_EQ(derive_text("axiom: A[B]C\nA < B -> X\n"), "A[X]C");
  // Nested: from D in A[B[C]D] the path is A B D.
  EXPECT_EQ(derive_text("axiom: A[B[C]D]\nB < D -> X\n"), "A[B[C]X]");
  EXPECT_EQ(derive_text("axiom: A[B[C]D]\nC < D -> X\n"), "A[B[C]D]");
  // Multi-module left context, read in order.
  EXPECT_EQ(derive_text("axiom: ABC\nA B < C -> X\n"), "ABX");
  EXPECT_EQ(derive_text("axiom: BAC\nA B < C -> X\n"), "BAC");
}

TEST(Context, RightContextSkipsWholeBranchesAndStopsAtTheEndOfTheBranch) {
  EXPECT_EQ(derive_text("axiom: A[C]B\nA > B -> X\n"), "X[C]B");
  EXPECT_EQ(derive_text("axiom: [A]B\nA > B -> X\n"), "[A]B");  // ']' ends A's branch
  EXPECT_EQ(derive_text("axiom: A[C[D]E]B\nA > B -> X\n"), "X[C[D]E]B");
  // Brackets in the pattern enter a branch (ABOP: A > [B]C).
  EXPECT_EQ(derive_text("axiom: A[B]C\nA > [B]C -> X\n"), "X[B]C");
  EXPECT_EQ(derive_text("axiom: A[BD]C\nA > [B]C -> X\n"), "X[BD]C");  // ']' skips the rest
  EXPECT_EQ(derive_text("axiom: A[D]C\nA > [B]C -> X\n"), "A[D]C");
}

TEST(Context, BothSidesWithNestedBranchesAndParameters) {
  EXPECT_EQ(derive_text("axiom: A(1)[X[Y]Z]B(2)[W]C(3)\nA(a) < B(b) > C(c) -> R(a+b+c)\n"),
            "A(1)[X[Y]Z]R(6)[W]C(3)");
}

TEST(Context, IgnoredModulesAreSkippedOnBothSides) {
  EXPECT_EQ(derive_text("ignore: + -\naxiom: A+-B-C\nA < B > C -> X\n"), "A+-X-C");
  EXPECT_EQ(derive_text("axiom: A+-B-C\nA < B > C -> X\n"), "A+-B-C");
  EXPECT_EQ(derive_text("#ignore: F\naxiom: AFFB\nA < B -> X\n"), "AFFX");
}

TEST(Context, ContextIsTheWordBeforeTheStep) {
  // Signal propagation (ABOP 1.8): one cell per step.
  const char* g = "axiom: BAAA\nB < A -> B\n";
  EXPECT_EQ(derive_text(g, steps(1)), "BBAA");
  EXPECT_EQ(derive_text(g, steps(2)), "BBBA");
}

TEST(Stochastic, SelectionFollowsTheProbabilitiesChiSquare) {
  // 10,000 modules each choose among three productions once.
  std::string axiom(10000, 'A');
  auto g = parse_ok("axiom: " + axiom + "\nA -> B : 0.2\nA -> C : 0.3\nA -> D : 0.5\n");
  auto w = derive(g, steps(1));
  ASSERT_TRUE(w.ok());
  std::map<std::string, int> counts;
  for (const Module& m : w->modules) ++counts[g.symbols.name(m.symbol)];
  const double expected[3] = {2000, 3000, 5000};
  const char* names[3] = {"B", "C", "D"};
  double chi2 = 0;
  for (int k = 0; k < 3; ++k) chi2 += std::pow(counts[names[k]] - expected[k], 2) / expected[k];
  EXPECT_LT(chi2, 13.82) << "B " << counts["B"] << " C " << counts["C"] << " D " << counts["D"];  // p = 0.001, 2 dof
  EXPECT_EQ(counts["B"] + counts["C"] + counts["D"], 10000);
}

TEST(Stochastic, WeightsAreNormalisedAndZeroWeightsNeverChosen) {
  std::string axiom(2000, 'A');
  auto g = parse_ok("axiom: " + axiom + "\nA -> B : 3\nA -> C : 0\nA -> D : 1\n");
  auto w = derive(g, steps(1));
  std::map<SymbolId, int> counts;
  for (const Module& m : w->modules) ++counts[m.symbol];
  SymbolId b, c, d;
  ASSERT_TRUE(g.symbols.find("B", &b) && g.symbols.find("C", &c) && g.symbols.find("D", &d));
  EXPECT_EQ(counts[c], 0);
  EXPECT_NEAR(counts[b] / 2000.0, 0.75, 0.05);
}

// Finite weights whose sum overflows still choose in proportion, not always the last.
TEST(Stochastic, WeightsWhoseSumOverflowsStillChooseInProportion) {
  std::string axiom(2000, 'A');
  auto g = parse_ok("axiom: " + axiom + "\nA -> B : 1.5e308\nA -> C : 1.5e308\n");
  auto w = derive(g, steps(1));
  ASSERT_TRUE(w.ok()) << w.error().format();
  SymbolId b;
  ASSERT_TRUE(g.symbols.find("B", &b));
  int count_b = 0;
  for (const Module& m : w->modules) count_b += m.symbol == b;
  EXPECT_NEAR(count_b / 2000.0, 0.5, 0.05);
}

TEST(Stochastic, ProbabilitiesThatAllSumToZeroAreAnError) {
  auto g = parse_ok("axiom: A\nA -> B : 0\nA -> C : 0\n");
  auto w = derive(g, steps(1));
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().loc.line, 2u);
  EXPECT_EQ(w.error().loc.column, 10u);
  EXPECT_NE(w.error().message.find("sum to 0"), std::string::npos);
}

TEST(Stochastic, ADeterministicFirstCandidateIsAppliedAndLaterOnesAreIgnored) {
  EXPECT_EQ(derive_text("axiom: AAAA\nA -> B\nA -> C : 0.5\n"), "BBBB");
  // After a stochastic candidate, a deterministic one is not a candidate.
  std::string out = derive_text("axiom: AAAAAAAA\nA -> C : 1\nA -> B\n");
  EXPECT_EQ(out, "CCCCCCCC");
}

TEST(Stochastic, TheSameSeedGivesTheSameWordAndAnotherSeedAnother) {
  const char* g = "seed: 7\naxiom: A\nA -> F(uniform(1,2))A : 0.5\nA -> F(rand())[+A]A : 0.5\n";
  std::string a = derive_text(g, steps(6));
  EXPECT_EQ(a, derive_text(g, steps(6)));
  DeriveOptions other = steps(6);
  other.seed = 8;
  EXPECT_NE(a, derive_text(g, other));
}

TEST(Stochastic, RandomAxiomArgumentsFollowTheSeed) {
  const char* g = "axiom: X(uniform(0, 360))Y(rand())\n";
  std::string a = derive_text(g, steps(0));
  EXPECT_EQ(a, derive_text(g, steps(0)));
  DeriveOptions other = steps(0);
  other.seed = 2;
  std::string b = derive_text(g, other);
  EXPECT_NE(a, b);
  // Two draws of one axiom are different numbers (one stream, not one draw each).
  auto gr = parse_ok(g);
  auto w = derive(gr, steps(0));
  EXPECT_NE(w->params[0] / 360.0, w->params[1]);
}

TEST(Stochastic, RandomFunctionsInHeaderValuesAreAnError) {
  Diagnostic d = testing::parse_error("#define A rand()\naxiom: F\n");
  EXPECT_EQ(d.loc.line, 1u);
  EXPECT_EQ(d.loc.column, 11u);
  EXPECT_NE(d.message.find("random functions are not allowed"), std::string::npos);
  EXPECT_NE(testing::parse_error("angle: uniform(1, 2)\naxiom: F\n").message.find("not allowed"), std::string::npos);
}

TEST(Stochastic, GaussDrawsHaveTheRequestedMeanAndSpread) {
  std::string axiom(4000, 'A');
  auto g = parse_ok("axiom: " + axiom + "\nA -> X(gauss(10, 2))\n");
  auto w = derive(g, steps(1));
  double sum = 0, sq = 0;
  for (double v : w->params) sum += v, sq += v * v;
  double mean = sum / 4000, var = sq / 4000 - mean * mean;
  EXPECT_NEAR(mean, 10, 0.15);
  EXPECT_NEAR(std::sqrt(var), 2, 0.1);
}

TEST(Cut, RemovesTheRestOfTheBranchAfterTheStep) {
  EXPECT_EQ(derive_text("axiom: F[AFF[G]F]B\nA -> %\n"), "F[]B");
  EXPECT_EQ(derive_text("axiom: FAF[G]F\nA -> %\n"), "F");  // at top level: to the end
  EXPECT_EQ(derive_text("axiom: F[X[Y]AZ]W\nA -> %\n"), "F[X[Y]]W");
}

TEST(Homomorphism, IsAppliedForTheTurtleOnlyAndRecursivelyToItsDepthLimit) {
  auto g = parse_ok("axiom: A\nA -> AB\nhomomorphism:\nB -> F C\nC -> +\n");
  auto w = derive(g, steps(2));
  EXPECT_EQ(print_word(*w, g.symbols), "ABB");  // the derived word is unchanged
  InterpretStats st;
  auto t = interpret(g, *w, {}, &st);
  EXPECT_EQ(print_word(*t, g.symbols), "AF+F+");
  EXPECT_EQ(st.still_expandable, 0u);

  auto deep = parse_ok("axiom: A\nsteps: 0\nmaximum depth: 3\nhomomorphism:\nA -> FA\n");
  auto dw = derive(deep);
  auto dt = interpret(deep, *dw, {}, &st);
  EXPECT_EQ(print_word(*dt, deep.symbols), "FFFA");
  EXPECT_EQ(st.still_expandable, 1u);
}

TEST(Limits, RunawayGrowthStopsAtMaxModulesWithAClearError) {
  auto g = parse_ok("axiom: A\nA -> AA\n");
  DeriveOptions o = steps(40);
  o.max_modules = 1000;
  auto w = derive(g, o);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("exceeds --max-modules (1000 modules)"), std::string::npos);
  EXPECT_NE(w.error().message.find("step 10"), std::string::npos);  // 2^10 = 1024 > 1000
}

TEST(Limits, PeakWordBytesPerModuleStayUnderSixteenForAContextFreeGrammar) {
  auto g = parse_ok("axiom: F\nF -> F[+F]F[-F]F\n");
  DeriveStats st;
  auto w = derive(g, steps(7), &st);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(st.modules, w->size());
  EXPECT_LE(static_cast<double>(st.peak_bytes) / static_cast<double>(st.modules), 16.0);
}

TEST(Words, PrintingAndReparsingRoundTrips) {
  auto g = parse_ok("module: Apex Ap\naxiom: F\n");
  const char* texts[] = {"F(1)[+(25.7)A(0.5,2)]B", "Ap ex", "Apex(1)Apex Ap", "F(0.1)F(1e+300)F(-2.5e-07)",
                         "A p", "[[F]]"};
  for (const char* text : texts) {
    auto w = parse_word(text, g);
    ASSERT_TRUE(w.ok()) << text << ": " << w.error().format();
    std::string printed = print_word(*w, g.symbols);
    auto again = parse_word(printed, g);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(print_word(*again, g.symbols), printed);
    EXPECT_EQ(again->params, w->params);
    ASSERT_EQ(again->size(), w->size());
  }
  EXPECT_EQ(print_word(*parse_word("Ap ex", g), g.symbols), "Ap ex");    // 'Apex' would merge
  EXPECT_EQ(print_word(*parse_word("A p", g), g.symbols), "A p");        // A then p, not the module Ap
}

TEST(Words, NumbersPrintInShortestRoundTripForm) {
  EXPECT_EQ(derive_text("axiom: F(0.1*3)F(1/3)F(100)F(1e21)F(-0)\nsteps: 0\n"),
            "F(0.30000000000000004)F(0.3333333333333333)F(100)F(1e+21)F(-0)");
}

// ---- progress and cancellation (core/util/progress.h) ---------------------------------

// Every fraction a Progress reported, in order.
struct Reports {
  std::vector<double> fractions;
  std::vector<std::string> stages;
  Progress progress(const std::atomic<bool>* cancel = nullptr) {
    return Progress([this](double f, std::string_view stage) {
      fractions.push_back(f);
      stages.emplace_back(stage);
    }, cancel);
  }
};

TEST(DeriveProgress, DerivationReportsMonotoneFractionsEndingAtOne) {
  auto g = parse_ok("axiom: A\nA -> AB\nB -> A\n");  // Fibonacci growth: 196418 modules at step 26
  Reports r;
  DeriveOptions o = steps(26);
  o.progress = r.progress();
  ASSERT_TRUE(derive(g, o).ok());
  ASSERT_GE(r.fractions.size(), 3u);  // within the long last steps too
  for (size_t i = 1; i < r.fractions.size(); ++i) EXPECT_LE(r.fractions[i - 1], r.fractions[i]);
  EXPECT_EQ(r.fractions.back(), 1.0);
  EXPECT_EQ(r.stages.back(), "derive");
}

TEST(DeriveProgress, CancellingMidDerivationStopsEarlyWithTheCancelledResult) {
  auto g = parse_ok("axiom: A\nA -> AA\n");
  std::atomic<bool> cancel{false};
  double last = 0;
  // Cancels as soon as a tenth is done; 2^24 modules at step 24 would follow.
  Progress progress([&](double f, std::string_view) {
    last = f;
    if (f >= 0.1) cancel.store(true);
  }, &cancel);
  DeriveOptions o = steps(24);
  o.progress = progress;
  DeriveStats st;
  auto w = derive(g, o, &st);
  ASSERT_FALSE(w.ok());
  EXPECT_TRUE(w.cancelled());
  EXPECT_TRUE(w.error().cancelled);
  EXPECT_EQ(w.error().message, "cancelled");
  EXPECT_LT(last, 1.0);
  EXPECT_EQ(st.modules, 0u);  // no stats: the derivation did not finish
}

TEST(DeriveProgress, CancellingMidStepStopsWithinTheStep) {
  auto g = parse_ok("axiom: A\nA -> AA\n");
  std::atomic<bool> cancel{false};
  int calls_after_cancel = 0;
  Progress progress([&](double f, std::string_view) {
    if (cancel.load()) ++calls_after_cancel;
    if (f > 21.5 / 22) cancel.store(true);  // half way through the last step (2^21 modules)
  }, &cancel);
  DeriveOptions o = steps(22);
  o.progress = progress;
  auto w = derive(g, o);
  EXPECT_TRUE(w.cancelled());
  EXPECT_EQ(calls_after_cancel, 0);  // checked at the very next chunk
}

TEST(DeriveProgress, ACancelledFlagStopsInterpretationToo) {
  auto g = parse_ok("axiom: A\nA -> AA\nhomomorphism:\nA -> FF\n");
  auto w = derive(g, steps(18));
  ASSERT_TRUE(w.ok());
  std::atomic<bool> cancel{true};
  DeriveOptions o;
  o.progress = Progress(&cancel);
  auto t = interpret(g, *w, o);
  EXPECT_TRUE(t.cancelled());
  cancel.store(false);
  Reports r;
  o.progress = r.progress(&cancel);
  ASSERT_TRUE(interpret(g, *w, o).ok());
  EXPECT_EQ(r.fractions.back(), 1.0);
  EXPECT_EQ(r.stages.back(), "interpret");
}

// docs/limits.md: --max-modules bounds the word's memory, so parameters count: a module
// with 65,535 parameters cannot slip under a limit meant for modules.
TEST(Limits, MaxModulesCountsEveryParameterAsAModule) {
  auto g = parse_ok("axiom: A(1,2,3)\nA(x,y,z) -> A(x,y,z)A(x,y,z)\n");
  DeriveOptions o = steps(3);
  o.max_modules = 32;  // 8 modules of 4 units each
  auto w = derive(g, o);
  ASSERT_TRUE(w.ok()) << w.error().format();
  EXPECT_EQ(w->size(), 8u);
  o.max_modules = 31;
  w = derive(g, o);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("exceeds --max-modules (31 modules), each parameter counting as a module"),
            std::string::npos)
      << w.error().message;
  o.max_modules = 3;  // the axiom alone is 4
  w = derive(g, o);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("the axiom exceeds --max-modules (3 modules)"), std::string::npos)
      << w.error().message;
}

}  // namespace
}  // namespace sylva::lsys
