// Passes and new context (docs/grammar-notes.md "Passes"): `pass: forward|backward` splits a
// step's productions into passes run in file order; `<<` and `>>` match context in the word the
// pass is writing, so a signal crosses the whole plant in one step. Checked against the fixed
// point of the same signal carried by old context (`<`, `>`) over as many steps as the word is long.
#include <random>
#include <string>

#include "tests/lsystem/lsystem_test_util.h"

namespace sylva::lsys {
namespace {

using testing::derive_text;
using testing::parse_error;
using testing::parse_ok;
using testing::steps;

TEST(Passes, BackwardNewRightContextCarriesASignalAcrossTheWholeWordInOneStep) {
  const std::string axiom = "axiom: A(0) A(0) A(0) B(5)\n";
  const std::string rules = "A(x) >> A(y) -> A(y + 1)\nA(x) >> B(y) -> A(y)\n";
  EXPECT_EQ(derive_text(axiom + "pass: backward\n" + rules, steps(1)), "A(7)A(6)A(5)B(5)");
  // With old context the signal moves one module per step.
  EXPECT_EQ(derive_text(axiom + "A(x) > A(y) -> A(y + 1)\nA(x) > B(y) -> A(y)\n", steps(1)), "A(1)A(1)A(5)B(5)");
}

TEST(Passes, ForwardNewLeftContextClimbsOutOfBranchesAndSkipsCompletedOnes) {
  const char* g =
      "axiom: B(1) [ A(0) ] A(0) [ A(0) [ A(0) ] A(0) ] A(0)\n"
      "A(p) << A(x) -> A(p + 1)\n"
      "B(p) << A(x) -> A(p + 1)\n";
  EXPECT_EQ(derive_text(g, steps(1)), "B(1)[A(2)]A(2)[A(3)[A(4)]A(4)]A(3)");
}

TEST(Passes, BackwardNewContextEntersBranchesOfTheNewWord) {
  // Basipetal: each internode the sum of what it carries, from tips T(1).
  const char* g =
      "axiom: I(0) [ I(0) [ T(1) ] T(1) ] I(0) [ T(1) ] T(1)\n"
      "pass: backward\n"
      "I(q) >> [ I(a) ] I(b) -> I(a + b)\n"
      "I(q) >> [ I(a) ] T(b) -> I(a + b)\n"
      "I(q) >> [ T(a) ] I(b) -> I(a + b)\n"
      "I(q) >> [ T(a) ] T(b) -> I(a + b)\n";
  EXPECT_EQ(derive_text(g, steps(1)), "I(4)[I(2)[T(1)]T(1)]I(2)[T(1)]T(1)");
}

// A random bracketed word of A(0), B, ignored turns and branches (some empty, some nested).
std::string random_word(std::mt19937& rng, int depth, int* budget) {
  std::string w;
  std::uniform_int_distribution<int> pick(0, 9);
  const int length = 1 + static_cast<int>(rng() % 6);
  for (int k = 0; k < length && *budget > 0; ++k, --*budget) {
    const int c = pick(rng);
    if (c < 5) w += "A(0)";
    else if (c < 6) w += "B";
    else if (c < 8) w += "+";
    else if (depth < 5) w += "[" + random_word(rng, depth + 1, budget) + "]";
    else w += "/";
  }
  return w;
}

// One backward step with `>>` and one forward step with `<<` give the fixed point that the
// same productions with old context reach after as many steps as the word is long: the new
// context sees its neighbours' values already final.
TEST(Passes, OneStepOfNewContextIsTheFixedPointOfOldContextOnRandomPlants) {
  std::mt19937 rng(20261206);
  const std::string basipetal =
      "A(x) R [ A(y) ] A(z) -> A(y + z + 1)\n"
      "A(x) R A(z) -> A(z + 1)\n"
      "A(x) R [ A(y) ] -> A(y + 1)\n"
      "A(x) -> A(1)\n";
  const std::string acropetal =
      "A(p) L A(x) -> A(p + 1)\n"
      "A(x) -> A(1)\n";
  auto with = [](std::string rules, const std::string& from, const std::string& to) {
    for (size_t at = rules.find(from); at != std::string::npos; at = rules.find(from, at + to.size()))
      rules.replace(at, from.size(), to);
    return rules;
  };
  int changed = 0;
  for (int trial = 0; trial < 200; ++trial) {
    int budget = 60;
    const std::string word = random_word(rng, 0, &budget);
    const std::string head = "ignore: + /\naxiom: " + word + "\n";
    const int64_t n = static_cast<int64_t>(word.size());
    const std::string old_up = derive_text(head + with(basipetal, " R ", " > "), steps(n));
    const std::string new_up = derive_text(head + "pass: backward\n" + with(basipetal, " R ", " >> "), steps(1));
    EXPECT_EQ(new_up, old_up) << word;
    EXPECT_EQ(new_up.find('<'), std::string::npos) << new_up;  // not an error
    const std::string old_down = derive_text(head + with(acropetal, " L ", " < "), steps(n));
    const std::string new_down = derive_text(head + with(acropetal, " L ", " << "), steps(1));
    EXPECT_EQ(new_down, old_down) << word;
    if (new_up != derive_text(head + with(basipetal, " R ", " > "), steps(1))) ++changed;
  }
  EXPECT_GT(changed, 100) << "most plants need more than one step of old context";
}

// A backward pass without new context rewrites exactly as a forward one: the same word, the
// same random numbers (streams keyed by module and step, not by the order of the scan).
TEST(Passes, ABackwardPassWithoutNewContextRewritesAsAForwardOne) {
  const std::string body =
      "A(x) > B(y) -> A(x + y) [ B(rand()) ] : 0.5\n"
      "A(x) -> B(x) A(uniform(0, 1)) : 0.5\n"
      "B(y) < A(x) -> B(y + x) : 0.7\n"
      "B(y) -> A(gauss(0, 1)) B(y) : 0.3\n";
  for (int seed = 1; seed <= 5; ++seed) {
    const std::string head = "seed: " + std::to_string(seed) + "\naxiom: A(1) [ B(2) ] A(3) B(0)\n";
    const std::string forward = derive_text(head + body, steps(5));
    EXPECT_EQ(derive_text(head + "pass: backward\n" + body, steps(5)), forward);
    EXPECT_EQ(forward.find("<"), std::string::npos) << forward;
  }
}

TEST(Passes, AStepRunsItsPassesInFileOrderEachOverTheWordThePassBeforeLeft) {
  const char* g =
      "derivation length: 2\n"
      "axiom: A\n"
      "A -> B\n"
      "pass: forward\n"
      "B -> C\n"
      "pass: backward\n"
      "C -> CD\n";
  EXPECT_EQ(derive_text(g, steps(1)), "CD");
  EXPECT_EQ(derive_text(g), "CDD");  // two steps: each runs all three passes
  // A first 'pass:' line before any production names the first pass's direction.
  Grammar one = parse_ok("axiom: A\npass: backward\nA -> B\n");
  ASSERT_EQ(one.passes.size(), 1u);
  EXPECT_TRUE(one.passes[0].backward);
  Grammar three = parse_ok(g);
  ASSERT_EQ(three.passes.size(), 3u);
  EXPECT_FALSE(three.passes[1].backward);
  EXPECT_TRUE(three.passes[2].backward);
  EXPECT_EQ(three.productions[2].pass, 2u);
}

TEST(Passes, LaterPassesDrawFromTheirOwnRandomStreams) {
  // The same stochastic production in two passes draws different numbers in each.
  const char* g =
      "seed: 3\n"
      "axiom: A(0)\n"
      "A(x) -> A(rand())\n"
      "pass: forward\n"
      "A(x) -> A(x) B(rand())\n";
  Grammar gr = parse_ok(g);
  auto w = derive(gr, steps(1));
  ASSERT_TRUE(w.ok());
  ASSERT_EQ(w->size(), 2u);
  EXPECT_NE(w->params[0], w->params[1]);
}

TEST(Passes, MisplacedNewContextAndPassesAreErrorsAtTheirPlace) {
  Diagnostic d = parse_error("axiom: A\nA >> B -> C\n");
  EXPECT_EQ(d.loc.line, 2u);
  EXPECT_EQ(d.loc.column, 3u);
  EXPECT_NE(d.message.find("pass: backward"), std::string::npos) << d.message;
  d = parse_error("axiom: A\npass: backward\nB << A -> C\n");
  EXPECT_EQ(d.loc.line, 3u);
  EXPECT_EQ(d.loc.column, 3u);
  EXPECT_NE(d.message.find("pass: forward"), std::string::npos) << d.message;
  d = parse_error("axiom: A\nhomomorphism:\nB << A -> C\n");
  EXPECT_EQ(d.loc.line, 3u);
  EXPECT_NE(d.message.find("homomorphism"), std::string::npos) << d.message;
  d = parse_error("axiom: A\nA -> B\npass: sideways\n");
  EXPECT_EQ(d.loc.line, 3u);
  EXPECT_EQ(d.loc.column, 7u);
  EXPECT_NE(d.message.find("'forward' or 'backward'"), std::string::npos) << d.message;
  d = parse_error("axiom: A\nA -> B\npass: backward\npass: forward\nB -> C\n");
  EXPECT_EQ(d.loc.line, 3u);
  EXPECT_NE(d.message.find("no productions"), std::string::npos) << d.message;
  d = parse_error("axiom: A\nA -> B\npass: backward\n");
  EXPECT_EQ(d.loc.line, 3u);
  d = parse_error("axiom: A\nhomomorphism:\npass: forward\nA -> B\n");
  EXPECT_EQ(d.loc.line, 3u);
  d = parse_error("axiom: A\nB << A << C -> D\n");
  EXPECT_NE(d.message.find("at most one left context"), std::string::npos) << d.message;
  d = parse_error("axiom: A\npass: backward\nA >> B > C -> D\n");
  EXPECT_NE(d.message.find("at most one right context"), std::string::npos) << d.message;
}

}  // namespace
}  // namespace sylva::lsys
