// Tests for the stable random streams of lsystem/derive.h, seen through the skeleton
// `sylva grow` builds (core/grow/turtle.h).
//
// Every module draws its random numbers from a stream keyed by (seed, lineage key, step),
// so changing a #define that only one kind of branch uses must leave every other branch
// bit-identical: the main axis, its internode lengths and branching angles, and every
// branch of another kind. The grammar below has a stochastic main apex A that emits
// lateral branches of type B (material 1) and C (material 2); BN is read only by B's
// production and sets how many internodes a B branch grows.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <map>
#include <string>

#include "core/geometry/skeleton.h"
#include "core/grow/turtle.h"
#include "core/grow/grow.h"
#include "lsystem/derive.h"
#include "lsystem/word.h"

namespace sylva {
namespace {

constexpr uint32_t kMainAxis = 0;  // material of A's internodes
constexpr uint32_t kBranchB = 1;   // '(1): the branch type BN changes
constexpr uint32_t kBranchC = 2;   // '(2): a branch type BN must not touch

// A is stochastic (three alternatives) and draws internode lengths and branching angles
// with uniform(); B and C draw their own internode lengths (and C its bending). A grows
// for 10 steps; a B started at step k ≤ 10 has 14 − k ≥ 4 steps left, so with BN = 3
// every B grows exactly 3 internodes and with BN = 5 at least 4: every B chain changes
// length, but no B chain appears or disappears, so chain indices line up.
constexpr const char* kGrammar = R"(# main axis with two stochastic branch types
#define BN 3
seed: 7
derivation length: 14
axiom: A(0)
A(n) : n < 10 -> F(uniform(0.5, 1)) [+(uniform(20, 40)) '(1) B(0)] /(137.5) A(n+1) : 0.4
A(n) : n < 10 -> F(uniform(0.5, 1)) [-(uniform(20, 40)) '(2) C(0)] /(137.5) A(n+1) : 0.4
A(n) : n < 10 -> F(uniform(0.5, 1)) [+(uniform(20, 40)) '(1) B(0)] [-(uniform(20, 40)) '(2) C(0)] A(n+1) : 0.2
B(n) : n < BN -> F(uniform(0.3, 0.6)) B(n+1)
C(n) : n < 4 -> F(uniform(0.2, 0.4)) +(uniform(-10, 10)) C(n+1)
)";

// Parses kGrammar with `overrides` (the -D values) and grows it.
Skeleton grow_branches(const std::map<std::string, double>& overrides, const lsys::DeriveOptions& options = {}) {
  lsys::ParseOptions parse_options;
  parse_options.define_overrides = overrides;
  sylva::Expected<lsys::Grammar> grammar = lsys::parse_grammar(kGrammar, "branches.lsys", parse_options);
  if (!grammar.ok()) {
    ADD_FAILURE() << grammar.error().format();
    return {};
  }
  sylva::Expected<GrowResult> grown = grow(*grammar, options, "branches.lsys", overrides);
  if (!grown.ok()) {
    ADD_FAILURE() << grown.error().format();
    return {};
  }
  return std::move(grown->skeleton);
}

// The material of chain `c`, checking that all its joints carry the same one.
uint32_t material_of(const Skeleton& skeleton, size_t c) {
  const Chain& chain = skeleton.chains[c];
  const uint32_t material = skeleton.joints[chain.first_joint].material;
  for (uint32_t j = 1; j < chain.joint_count; ++j)
    EXPECT_EQ(skeleton.joints[chain.first_joint + j].material, material) << "chain " << c << " joint " << j;
  return material;
}

bool same_bits(double a, double b) { return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b); }

// Chain `c` of `a` and of `b` are bit-for-bit the same: parent, joint count, and every
// joint's position, radius and material.
testing::AssertionResult chains_bit_identical(const Skeleton& a, const Skeleton& b, size_t c) {
  const Chain& ca = a.chains[c];
  const Chain& cb = b.chains[c];
  if (ca.parent != cb.parent) return testing::AssertionFailure() << "chain " << c << ": parents differ";
  if (ca.joint_count != cb.joint_count)
    return testing::AssertionFailure() << "chain " << c << ": " << ca.joint_count << " joints vs "
                                       << cb.joint_count;
  for (uint32_t j = 0; j < ca.joint_count; ++j) {
    const Joint& ja = a.joints[ca.first_joint + j];
    const Joint& jb = b.joints[cb.first_joint + j];
    bool same = same_bits(ja.radius_m, jb.radius_m) && ja.material == jb.material;
    for (int k = 0; k < 3; ++k) same = same && same_bits(ja.position_m[k], jb.position_m[k]);
    if (!same)
      return testing::AssertionFailure()
             << "chain " << c << " joint " << j << ": (" << ja.position_m[0] << ", " << ja.position_m[1]
             << ", " << ja.position_m[2] << ") vs (" << jb.position_m[0] << ", " << jb.position_m[1] << ", "
             << jb.position_m[2] << ")";
  }
  return testing::AssertionSuccess();
}

std::string chains_json(Skeleton skeleton) {
  skeleton.source = {};  // compare the plant, not the record of how it was made
  return write_skeleton_json(skeleton);
}

TEST(StableStreams, DefineUsedOnlyByOneBranchTypeLeavesEveryOtherBranchBitIdentical) {
  const Skeleton short_b = grow_branches({});
  const Skeleton long_b = grow_branches({{"BN", 5}});
  ASSERT_EQ(short_b.chains.size(), long_b.chains.size()) << "B branches must change length, not number";
  ASSERT_GT(short_b.chains.size(), 3u);

  size_t main_chains = 0, b_chains = 0, c_chains = 0;
  for (size_t c = 0; c < short_b.chains.size(); ++c) {
    SCOPED_TRACE("chain " + std::to_string(c));
    const uint32_t material = material_of(short_b, c);
    ASSERT_EQ(material_of(long_b, c), material) << "chain indices do not line up";
    if (material == kBranchB) {
      ++b_chains;
      // A B branch still starts at the same joint of the main axis, in the same place...
      EXPECT_EQ(short_b.chains[c].parent, long_b.chains[c].parent);
      const Joint& first_short = short_b.joints[short_b.chains[c].first_joint];
      const Joint& first_long = long_b.joints[long_b.chains[c].first_joint];
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(same_bits(first_short.position_m[k], first_long.position_m[k]));
      // ...but grows BN internodes: 3 with BN = 3, at least 4 with BN = 5.
      EXPECT_EQ(short_b.chains[c].joint_count, 4u);
      EXPECT_GE(long_b.chains[c].joint_count, 5u);
      EXPECT_FALSE(chains_bit_identical(short_b, long_b, c));
    } else {
      main_chains += material == kMainAxis;
      c_chains += material == kBranchC;
      EXPECT_TRUE(material == kMainAxis || material == kBranchC) << "material " << material;
      EXPECT_TRUE(chains_bit_identical(short_b, long_b, c));
    }
  }
  EXPECT_EQ(main_chains, 1u);
  EXPECT_GT(b_chains, 0u);
  EXPECT_GT(c_chains, 0u);
  // The main axis really is random: its internodes are not all the same length.
  const Chain& axis = short_b.chains[0];
  ASSERT_GE(axis.joint_count, 3u);
  const Joint* j = &short_b.joints[axis.first_joint];
  EXPECT_NE(j[1].position_m[1] - j[0].position_m[1], j[2].position_m[1] - j[1].position_m[1]);
}

TEST(StableStreams, SameGrammarAndSeedGiveByteIdenticalSkeletonFiles) {
  const std::string first = write_skeleton_json(grow_branches({}));
  const std::string second = write_skeleton_json(grow_branches({}));
  EXPECT_EQ(first, second);
  // The grammar's seed: 7 and an explicit --seed 7 are the same plant.
  lsys::DeriveOptions seven;
  seven.seed = 7;
  EXPECT_EQ(write_skeleton_json(grow_branches({}, seven)), first);
}

TEST(StableStreams, DifferentSeedGivesADifferentPlant) {
  lsys::DeriveOptions other;
  other.seed = 8;
  const Skeleton seeded_7 = grow_branches({});
  const Skeleton seeded_8 = grow_branches({}, other);
  EXPECT_EQ(seeded_8.source.seed, 8u);
  EXPECT_NE(write_skeleton_json(seeded_7), write_skeleton_json(seeded_8));
  // Not only the recorded seed: the geometry itself differs.
  EXPECT_NE(chains_json(seeded_7), chains_json(seeded_8));
}

TEST(StableStreams, DefineOverrideIsRecordedInTheSkeletonSource) {
  const Skeleton skeleton = grow_branches({{"BN", 5}});
  EXPECT_EQ(skeleton.source.defines, (std::map<std::string, double>{{"BN", 5}}));
  EXPECT_EQ(skeleton.source.seed, 7u);
  EXPECT_EQ(skeleton.source.steps, 14);
}

// What the keys promise, exactly (docs/grammar-notes.md "Random numbers"): a module's key
// is its lineage — its place in the axiom, then its place in each successor that made it.
// Modules added after it, or anything another production draws, leave its numbers alone;
// a module inserted before it in the axiom (or in its own successor) gives it another
// place, hence other numbers — the "F(2) before Crown(0)" edit the README warns about.
std::string derived_word(const std::string& axiom, const std::string& extra_productions = {}) {
  const std::string text = "seed: 3\nderivation length: 6\naxiom: " + axiom +
                           "\nA(n) : n < 6 -> F(uniform(0.5, 1)) [+(uniform(10, 50)) A(n+1)] A(n+1) : 0.5\n"
                           "A(n) : n < 6 -> F(uniform(0.5, 1)) A(n+1) : 0.5\n" +
                           extra_productions;
  sylva::Expected<lsys::Grammar> grammar = lsys::parse_grammar(text, "crown.lsys");
  if (!grammar.ok()) {
    ADD_FAILURE() << grammar.error().format();
    return {};
  }
  sylva::Expected<lsys::Word> word = lsys::derive(*grammar);
  if (!word.ok()) {
    ADD_FAILURE() << word.error().format();
    return {};
  }
  return lsys::print_word(*word, grammar->symbols);
}

TEST(StableStreams, ModulesAfterAndOtherProductionsLeaveAModuleAloneAModuleBeforeItMovesItsKey) {
  const std::string crown = derived_word("A(0)");
  ASSERT_GT(crown.size(), 40u);
  // Appended after the crown, with and without a random production of its own.
  const std::string appended = derived_word("A(0) G(2)");
  EXPECT_TRUE(appended.starts_with(crown)) << appended;
  const std::string other_rule = derived_word("A(0) G(2)", "G(x) -> G(x) F(uniform(0, 1))\n");
  EXPECT_TRUE(other_rule.starts_with(crown)) << other_rule;
  EXPECT_NE(other_rule, appended);  // G's rule did draw
  // Inserted before it: the crown's place in the axiom, and so its numbers, change.
  const std::string inserted = derived_word("G(2) A(0)");
  EXPECT_FALSE(inserted.ends_with(crown)) << inserted;
  // Not a different shape by accident of the rule: the crown's own words differ.
  EXPECT_NE(inserted.substr(inserted.find('F')), crown.substr(crown.find('F')));
}

}  // namespace
}  // namespace sylva
