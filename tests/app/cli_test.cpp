// cli_test.cpp — the `sylva` command line contract (docs/spec/cli.md, docs/spec/grammar.md "Printing a
// word", docs/spec/skeleton.md "File format"): exit statuses 0/1/2, help texts, the exact word
// `derive` prints, how -n/--seed/-D override the grammar, grow's summary line and
// deterministic, atomic output, and the --max-modules guard against runaway growth.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "tests/support/process.h"

namespace {

namespace fs = std::filesystem;

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

// ABOP Fig 1.24-style bracketed grammar used by many tests.
constexpr const char* kBracketed = "axiom: F\nF -> F[+F]F\n";
// A grammar with a define, so -D N=... is legal on it.
constexpr const char* kWithDefine = "#define N 3\naxiom: A(N)\n";
// Doubles every step: 2^40 modules after 40 steps unless --max-modules stops it.
constexpr const char* kRunaway = "derivation length: 40\naxiom: A\nA -> AA\n";
// Always fails: the '[' is never closed.
constexpr const char* kBroken = "axiom: F[+F\n";

std::string join(const std::vector<std::string>& args) {
  std::string text;
  for (const std::string& a : args) text += (text.empty() ? "" : " ") + a;
  return text;
}

// Runs `sylva ARGS...` and returns stdout, recording a failure unless it exits 0.
std::string sylva_ok(const std::vector<std::string>& args, const std::string& cwd = {}) {
  ProcessResult r = run_sylva(args, cwd);
  if (crashed(r) || r.exit_code != 0) ADD_FAILURE() << "sylva " << join(args) << " failed\n" << describe(r);
  return r.out;
}

// Runs `sylva derive ARGS...` and returns the printed word (with its newline).
std::string derive(std::vector<std::string> args) {
  args.insert(args.begin(), "derive");
  return sylva_ok(args);
}

// True when `flag` occurs in `text` as a whole flag (not inside "--max-modules" or
// "non-negative").
bool mentions_flag(const std::string& text, const std::string& flag) {
  auto part_of_flag = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'; };
  for (size_t at = text.find(flag); at != std::string::npos; at = text.find(flag, at + 1)) {
    bool starts = at == 0 || !part_of_flag(text[at - 1]);
    bool ends = at + flag.size() == text.size() || !part_of_flag(text[at + flag.size()]);
    if (starts && ends) return true;
  }
  return false;
}

class CliTest : public ::testing::Test {
 protected:
  // Writes a grammar into the test's temporary folder and returns its path.
  std::string grammar(const std::string& name, const std::string& text) { return dir_.write(name, text); }
  TempDir dir_;
};

// ---------------------------------------------------------------------------------------
// Exit status 2: usage errors. Every case also must not create the output file.

struct UsageCase {
  std::string name;
  std::vector<std::string> args;  // "{G}": a valid grammar defining N; "{O}": an output path
};

void PrintTo(const UsageCase& c, std::ostream* os) { *os << "sylva " << join(c.args); }

const std::vector<UsageCase>& usage_cases() {
  static const std::vector<UsageCase> cases = {
      {"NoArguments", {}},
      {"UnknownSubcommand", {"frobnicate"}},
      {"UnknownTopLevelFlag", {"--frobnicate"}},
      {"UnknownDeriveFlag", {"derive", "{G}", "--frobnicate"}},
      {"UnknownGrowFlag", {"grow", "{G}", "-o", "{O}", "--frobnicate"}},
      {"DeriveWithoutGrammar", {"derive"}},
      {"DeriveWithTwoGrammars", {"derive", "{G}", "{G}"}},
      {"GrowWithoutOutput", {"grow", "{G}"}},
      {"GrowWithoutGrammar", {"grow", "-o", "{O}"}},
      {"MissingValueOfN", {"derive", "{G}", "-n"}},
      {"MissingValueOfSeed", {"derive", "{G}", "--seed"}},
      {"MissingValueOfD", {"derive", "{G}", "-D"}},
      {"MissingValueOfMaxModules", {"derive", "{G}", "--max-modules"}},
      {"MissingValueOfOutput", {"grow", "{G}", "-o"}},
      {"StepsNotANumber", {"derive", "{G}", "-n", "abc"}},
      {"StepsEmpty", {"derive", "{G}", "-n", ""}},
      {"StepsFractional", {"derive", "{G}", "-n", "1.5"}},
      {"StepsNegative", {"derive", "{G}", "-n", "-1"}},
      {"StepsTrailingGarbage", {"derive", "{G}", "-n", "2x"}},
      {"StepsHex", {"derive", "{G}", "-n", "0x10"}},
      {"GrowStepsNegative", {"grow", "{G}", "-o", "{O}", "-n", "-1"}},
      {"SeedNegative", {"derive", "{G}", "--seed", "-1"}},
      {"SeedTwoToThe64", {"derive", "{G}", "--seed", "18446744073709551616"}},
      {"SeedFarTooLarge", {"derive", "{G}", "--seed", "99999999999999999999999"}},
      {"SeedFractional", {"derive", "{G}", "--seed", "1.5"}},
      {"SeedExponent", {"derive", "{G}", "--seed", "1e3"}},
      {"SeedNotANumber", {"derive", "{G}", "--seed", "abc"}},
      {"SeedHex", {"derive", "{G}", "--seed", "0x10"}},
      {"GrowSeedNotANumber", {"grow", "{G}", "-o", "{O}", "--seed", "abc"}},
      {"DefineWithoutEquals", {"derive", "{G}", "-D", "N"}},
      {"DefineEmptyValue", {"derive", "{G}", "-D", "N="}},
      {"DefineNotANumber", {"derive", "{G}", "-D", "N=abc"}},
      {"DefineTrailingGarbage", {"derive", "{G}", "-D", "N=1x"}},
      {"DefineEmptyName", {"derive", "{G}", "-D", "=1"}},
      {"DefineUnknownName", {"derive", "{G}", "-D", "M=1"}},
      {"DefineInfinity", {"derive", "{G}", "-D", "N=inf"}},
      {"DefineNaN", {"derive", "{G}", "-D", "N=nan"}},
      {"DefineHex", {"derive", "{G}", "-D", "N=0x10"}},
      {"DefineOutOfRange", {"derive", "{G}", "-D", "N=1e400"}},
      {"GrowDefineUnknownName", {"grow", "{G}", "-o", "{O}", "-D", "M=1"}},
      {"MaxModulesZero", {"derive", "{G}", "--max-modules", "0"}},
      {"MaxModulesNegative", {"derive", "{G}", "--max-modules", "-5"}},
      {"MaxModulesNotANumber", {"derive", "{G}", "--max-modules", "abc"}},
      {"GrowMaxModulesZero", {"grow", "{G}", "-o", "{O}", "--max-modules", "0"}},
      // '..' undoes the folder the placeholder names: three seeds onto one file (issue 32).
      {"GrowSeedsFoldedOntoOneFile", {"grow", "{G}", "--seed", "1..3", "-o", "out/{seed}/../same.skel.json"}},
      {"ExportSeedsFoldedOntoOneFile", {"export", "{G}", "--seed", "1..3", "-o", "{seed}/../same.glb"}},
      // The backend flag is one table for render and studio: a bad value is a usage
      // error before any window or context is made.
      {"RenderBackendUnknown", {"render", "{G}", "--backend", "BAD", "-o", "x.png"}},
      {"StudioBackendUnknown", {"studio", "{G}", "--backend", "BAD"}},
      {"StudioBackendEmpty", {"studio", "{G}", "--backend", ""}},
      {"FramesFoldedOntoOneFile",
       {"render", "{G}", "--frames", "1..3", "-o", "f/{frame}/../same.png", "--width", "8", "--height", "8"}},
  };
  return cases;
}

class UsageErrorTest : public ::testing::TestWithParam<UsageCase> {};

TEST_P(UsageErrorTest, ExitsTwoWithAMessageOnStderrAndWritesNothing) {
  TempDir dir;
  const std::string grammar_path = dir.write("g.lsys", kWithDefine);
  const std::string output_path = dir.file("out.skel.json");
  std::vector<std::string> args = GetParam().args;
  for (std::string& a : args) {
    if (a == "{G}") a = grammar_path;
    if (a == "{O}") a = output_path;
  }
  ProcessResult r = run_sylva(args, dir.path().string());
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 2) << "sylva " << join(args) << "\n" << describe(r);
  EXPECT_FALSE(r.err.empty()) << "a usage error must say what is wrong on stderr\n" << describe(r);
  EXPECT_EQ(r.out, "") << "a usage error must print nothing on stdout\n" << describe(r);
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"g.lsys"}) << "no output, no temporary files";
}

INSTANTIATE_TEST_SUITE_P(Cli, UsageErrorTest, ::testing::ValuesIn(usage_cases()),
                         [](const ::testing::TestParamInfo<UsageCase>& info) { return info.param.name; });

// The edges of the legal ranges are accepted.
TEST_F(CliTest, LegalEdgeValuesOfFlagsAreAccepted) {
  const std::string g = grammar("g.lsys", kWithDefine);
  EXPECT_EQ(derive({g, "-n", "0"}), "A(3)\n");
  EXPECT_EQ(derive({g, "--seed", "0"}), "A(3)\n");
  EXPECT_EQ(derive({g, "--seed", "18446744073709551615"}), "A(3)\n");
  EXPECT_EQ(derive({g, "--max-modules", "2"}), "A(3)\n");  // a module and its parameter
  EXPECT_EQ(derive({g, "-D", "N=0"}), "A(0)\n");
}

TEST_F(CliTest, OptionsMayComeBeforeTheGrammar) {
  const std::string g = grammar("g.lsys", kBracketed);
  EXPECT_EQ(derive({"-n", "1", g}), "F[+F]F\n");
}

// Exit status 1: the input cannot be read.
TEST_F(CliTest, MissingGrammarFileExitsOneNamingIt) {
  const std::string missing = dir_.file("no-such-grammar.lsys");
  ProcessResult r = run_sylva({"derive", missing});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("no-such-grammar.lsys"), std::string::npos) << describe(r);
  EXPECT_EQ(r.out, "");
}

TEST_F(CliTest, FolderGivenAsGrammarExitsOne) {
  ProcessResult r = run_sylva({"derive", dir_.path().string()});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  // A folder is read as a vlab object (docs/cpfg.md); one without 'specifications' is said
  // to be no vlab object, not a grammar without an axiom (docs/limits.md "Inputs").
  EXPECT_NE(r.err.find("not a vlab object"), std::string::npos) << describe(r);
  EXPECT_NE(r.err.find("specifications"), std::string::npos) << describe(r);
  EXPECT_EQ(r.err.find("axiom"), std::string::npos) << describe(r);
}

TEST_F(CliTest, ADeviceGivenAsGrammarIsRefusedWithoutReadingIt) {
  ProcessResult r = run_sylva({"derive", "/dev/zero"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("/dev/zero: error: cannot read: it is a character device"), std::string::npos) << describe(r);
  EXPECT_LT(r.max_rss_kb, 512 * 1024) << describe(r);
}

TEST_F(CliTest, UnwritableOutputExitsOneAndCreatesNothing) {
  const std::string g = grammar("g.lsys", kBracketed);
  const std::string output = dir_.file("no-such-folder/plant.skel.json");
  ProcessResult r = run_sylva({"grow", g, "-o", output});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("no-such-folder"), std::string::npos) << "the message should name the path\n" << describe(r);
  EXPECT_EQ(list_dir(dir_.path()), std::vector<std::string>{"g.lsys"});
}

// ---------------------------------------------------------------------------------------
// Help: exit 0, usage on stdout, every flag mentioned.

TEST(CliHelp, TopLevelHelpListsTheSubcommands) {
  ProcessResult r = run_sylva({"--help"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("derive"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("grow"), std::string::npos) << r.out;
}

TEST(CliHelp, TopLevelHelpListsEveryBenchmarkAndVersionWorks) {
  ProcessResult r = run_sylva({"--help"});
  for (const char* bench : {"bench  lsystem", "bench  raycast", "bench  geometry", "bench  gpu", "bench  fog",
                            "bench  studio", "studio", "export", "render"})
    EXPECT_NE(r.out.find(bench), std::string::npos) << bench << "\n" << r.out;
  r = run_sylva({"--version"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_TRUE(std::regex_match(r.out, std::regex("sylva [0-9]+\\.[0-9]+\\.[0-9]+\n"))) << r.out;
}

TEST(CliHelp, DeriveHelpMentionsEveryFlag) {
  ProcessResult r = run_sylva({"derive", "--help"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_EQ(r.err, "");
  for (const char* flag : {"-n", "--seed", "-D", "--max-modules", "--help"})
    EXPECT_TRUE(mentions_flag(r.out, flag)) << "derive --help should mention " << flag << ":\n" << r.out;
}

TEST(CliHelp, GrowHelpMentionsEveryFlagAndNeedsNoOutputFlag) {
  ProcessResult r = run_sylva({"grow", "--help"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 0) << "--help wins over the missing -o\n" << describe(r);
  EXPECT_EQ(r.err, "");
  for (const char* flag : {"-n", "--seed", "-D", "--max-modules", "-o", "--help"})
    EXPECT_TRUE(mentions_flag(r.out, flag)) << "grow --help should mention " << flag << ":\n" << r.out;
}

// ---------------------------------------------------------------------------------------
// derive: the exact word, worked out by hand.

TEST_F(CliTest, DeriveRewritesBracketedGrammarInParallel) {
  const std::string g = grammar("g.lsys", kBracketed);
  EXPECT_EQ(derive({g, "-n", "0"}), "F\n");
  EXPECT_EQ(derive({g}), "F[+F]F\n") << "the default derivation length is 1";
  EXPECT_EQ(derive({g, "-n", "1"}), "F[+F]F\n");
  EXPECT_EQ(derive({g, "-n", "2"}), "F[+F]F[+F[+F]F]F[+F]F\n");
}

TEST_F(CliTest, DerivationLengthDirectiveAndItsAliasSetTheSteps) {
  const std::string g = grammar("g.lsys", std::string("derivation length: 2\n") + kBracketed);
  const std::string alias = grammar("alias.lsys", std::string("steps: 2\n") + kBracketed);
  EXPECT_EQ(derive({g}), "F[+F]F[+F[+F]F]F[+F]F\n");
  EXPECT_EQ(derive({alias}), "F[+F]F[+F[+F]F]F[+F]F\n");
}

TEST_F(CliTest, StepsFlagOverridesTheDerivationLengthDirective) {
  const std::string g = grammar("g.lsys", std::string("derivation length: 2\n") + kBracketed);
  EXPECT_EQ(derive({g, "-n", "1"}), "F[+F]F\n");
  EXPECT_EQ(derive({g, "-n", "0"}), "F\n");
}

TEST_F(CliTest, DerivePrintsParametersInShortestRoundTripForm) {
  const std::string g = grammar("g.lsys", "axiom: X(1)\nX(x) -> F(x)[+(25.7)A(x/2,x*2)]B\n");
  EXPECT_EQ(derive({g}), "F(1)[+(25.7)A(0.5,2)]B\n");
  const std::string numbers = grammar("numbers.lsys", "axiom: X\nX -> A(0.1+0.2,1/3,-2.5,100,0.25*4)\n");
  EXPECT_EQ(derive({numbers}), "A(0.30000000000000004,0.3333333333333333,-2.5,100,1)\n");
}

TEST_F(CliTest, ModulesWithoutProductionsAreCopiedAndEmptySuccessorsErase) {
  EXPECT_EQ(derive({grammar("copy.lsys", "axiom: AB\nA -> AA\n")}), "AAB\n");
  EXPECT_EQ(derive({grammar("erase.lsys", "axiom: FAF\nA ->\n")}), "FF\n");
}

TEST_F(CliTest, ContextSensitiveSignalPropagatesOneModulePerStep) {
  // ABOP section 1.8: an acropetal signal b moving along a string of a's.
  const std::string g = grammar("g.lsys", "axiom: baaaa\nb < a -> b\nb -> a\n");
  EXPECT_EQ(derive({g, "-n", "1"}), "abaaa\n");
  EXPECT_EQ(derive({g, "-n", "2"}), "aabaa\n");
}

TEST_F(CliTest, ConditionsChooseTheProduction) {
  const std::string g = grammar("g.lsys", "axiom: A(0)\nA(x) : x < 3 -> A(x+1)F\nA(x) : x >= 3 -> B\n");
  EXPECT_EQ(derive({g, "-n", "3"}), "A(3)FFF\n");
  EXPECT_EQ(derive({g, "-n", "5"}), "BFFF\n");
}

TEST_F(CliTest, NotationVariantsOfTheBookAreAccepted) {
  EXPECT_EQ(derive({grammar("omega.lsys", "ω: F\nF -> FF\n")}), "FF\n");
  EXPECT_EQ(derive({grammar("arrow.lsys", "axiom: F\nF --> FF\n")}), "FF\n");
  EXPECT_EQ(derive({grammar("roll.lsys", "axiom: F//F\n")}), "F//F\n") << "'//' is two roll commands";
  EXPECT_EQ(derive({grammar("crlf.lsys", "axiom: F\r\nF -> FF\r\n")}), "FF\n") << "CRLF line endings";
  EXPECT_EQ(derive({grammar("comments.lsys",
                            "# a comment line\naxiom: F /* trunk */\nF -> F[+F]F /* ABOP */\n")}),
            "F[+F]F\n");
}

TEST_F(CliTest, PrintedWordWithMultiCharacterModulesReadsBackAsTheSameWord) {
  // docs/spec/grammar.md: multi-character modules are followed by a space where the next module
  // would otherwise merge with them. Whatever the spacing, the printed word must parse
  // back to itself.
  const std::string g = grammar("g.lsys",
                                "module: Apex Bud\naxiom: Apex\nApex -> F Bud Bud(2) F Apex Apex\n");
  const std::string word = derive({g});
  ASSERT_FALSE(word.empty());
  ASSERT_EQ(word.back(), '\n');
  const std::string again =
      grammar("again.lsys", "module: Apex Bud\naxiom: " + word.substr(0, word.size() - 1) + "\n");
  EXPECT_EQ(derive({again, "-n", "0"}), word);
}

TEST_F(CliTest, PrintedMultiCharacterModuleIsSeparatedWhereItWouldMergeWithTheNext) {
  // Ap followed by e and x must not print as "Apex", which reads back as the module Apex.
  const std::string g = grammar("g.lsys", "module: Ap Apex\naxiom: X\nX -> Ap e x Apex Ap\n");
  const std::string word = derive({g});
  ASSERT_FALSE(word.empty());
  // Read the printed word back and tell the modules apart by rewriting them.
  const std::string again = grammar(
      "again.lsys", "module: Ap Apex\naxiom: " + word.substr(0, word.size() - 1) + "\nAp -> B\nApex -> C\n");
  EXPECT_EQ(derive({again}), "BexCB\n") << "printed word: " << word;
}

// ---------------------------------------------------------------------------------------
// --seed and -D override the grammar.

std::string stochastic_grammar(int seed) {
  return "seed: " + std::to_string(seed) + "\naxiom: " + std::string(32, 'A') +
         "\nA -> B : 0.5\nA -> C : 0.5\n";
}

TEST_F(CliTest, SeedFlagOverridesTheSeedDirective) {
  const std::string seeded7 = grammar("seven.lsys", stochastic_grammar(7));
  const std::string seeded1 = grammar("one.lsys", stochastic_grammar(1));
  const std::string word7 = derive({seeded7});
  EXPECT_EQ(word7.size(), 33u) << word7;
  EXPECT_EQ(derive({seeded1, "--seed", "7"}), word7);
  EXPECT_NE(derive({seeded1}), word7) << "seeds 1 and 7 should draw differently (32 coin flips)";
  EXPECT_NE(derive({seeded7, "--seed", "8"}), word7);
}

TEST_F(CliTest, SameSeedGivesTheSameDrawsEveryRun) {
  const std::string g = grammar("g.lsys", "axiom: AAA\nA -> B(rand())C(uniform(2,3))\n");
  const std::string first = derive({g, "--seed", "12345"});
  EXPECT_EQ(derive({g, "--seed", "12345"}), first);
  EXPECT_NE(derive({g, "--seed", "12346"}), first);
  EXPECT_EQ(derive({g, "--seed", "18446744073709551615"}), derive({g, "--seed", "18446744073709551615"}));
}

TEST_F(CliTest, DefineFlagOverridesDefinesAndWhatDependsOnThem) {
  const std::string g = grammar("g.lsys", "#define N 3\n#define M N*2\naxiom: A(N,M)\n");
  EXPECT_EQ(derive({g}), "A(3,6)\n");
  EXPECT_EQ(derive({g, "-D", "N=5"}), "A(5,10)\n");
  EXPECT_EQ(derive({g, "-D", "N=2.5"}), "A(2.5,5)\n");
  EXPECT_EQ(derive({g, "-D", "N=-1"}), "A(-1,-2)\n");
  EXPECT_EQ(derive({g, "-D", "N=1e3"}), "A(1000,2000)\n");
  EXPECT_EQ(derive({g, "-D", "N=5", "-D", "M=1"}), "A(5,1)\n");
}

TEST_F(CliTest, DefineFlagReachesDirectivesButStepsFlagWins) {
  const std::string g = grammar("g.lsys", "#define K 1\nderivation length: K\naxiom: F\nF -> FF\n");
  EXPECT_EQ(derive({g}), "FF\n");
  EXPECT_EQ(derive({g, "-D", "K=3"}), "FFFFFFFF\n");
  EXPECT_EQ(derive({g, "-D", "K=3", "-n", "1"}), "FF\n");
}

// ---------------------------------------------------------------------------------------
// grow: summary line, file contents, determinism.

// Parses "[x,y,z]" into three numbers; false if it is not that.
bool parse_point(const std::string& text, double point[3]) {
  const char* at = text.c_str();
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    point[i] = std::strtod(at, &end);
    if (end == at) return false;
    at = end;
    while (*at == ' ') ++at;
    if (i < 2 && *at++ != ',') return false;
  }
  return *at == '\0';
}

TEST_F(CliTest, GrowPrintsOneSummaryLineAndWritesTheSkeleton) {
  const std::string g = grammar("g.lsys", kBracketed);
  const std::string output = dir_.file("plant.skel.json");
  ProcessResult r = run_sylva({"grow", g, "-o", output});
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);

  // F[+F]F with the default 90 degree angle and step 1: a trunk (0,0,0)-(0,1,0)-(0,2,0)
  // and a branch from (0,1,0) turned toward L = -X to (-1,1,0). The box may bound the
  // joints or the joints grown by their radius (default width 0.05); either is fine.
  static const std::regex summary(
      R"(^(.*): (\d+) modules, (\d+) chains, (\d+) segments, bbox \[([^\]]*)\]\.\.\[([^\]]*)\] m, ([0-9.eE+-]+) ms\n$)");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(r.out, m, summary)) << "summary line: '" << r.out << "'";
  EXPECT_EQ(m[1].str(), g);
  EXPECT_EQ(m[2].str(), "6");
  EXPECT_EQ(m[3].str(), "2");
  EXPECT_EQ(m[4].str(), "3");
  double low[3], high[3];
  ASSERT_TRUE(parse_point(m[5].str(), low)) << m[5].str();
  ASSERT_TRUE(parse_point(m[6].str(), high)) << m[6].str();
  const double joints_low[3] = {-1, 0, 0}, joints_high[3] = {0, 2, 0};
  bool bbox_ok = false;
  for (double radius : {0.0, 0.05}) {
    bool matches = true;
    for (int i = 0; i < 3; ++i) {
      matches = matches && std::abs(low[i] - (joints_low[i] - radius)) < 1e-6 &&
                std::abs(high[i] - (joints_high[i] + radius)) < 1e-6;
    }
    bbox_ok = bbox_ok || matches;
  }
  EXPECT_TRUE(bbox_ok) << "bbox should be [-1,0,0]..[0,2,0], or that grown by the radius 0.05: " << r.out;

  const std::string json = read_file(output);
  EXPECT_NE(json.find("\"sylva-skeleton\""), std::string::npos) << json;
  EXPECT_TRUE(std::regex_search(json, std::regex(R"("version"\s*:\s*1\b)"))) << json;
  EXPECT_EQ(list_dir(dir_.path()), (std::vector<std::string>{"g.lsys", "plant.skel.json"}));
}

// A polygon is a leaf: grow's summary counts the leaves after the time, and its box holds
// their vertices (a plant of one leaf and no segment has the leaf's box, not a point);
// export's counts them after the segments.
TEST_F(CliTest, GrowAndExportCountTheLeavesAndGrowBoxesThem) {
  const std::string g = grammar("leaf.lsys", "angle: 90\nstep: 1\naxiom: {.f.+f.+f.}\n");
  ProcessResult r = run_sylva({"grow", g, "-o", dir_.file("leaf.skel.json")});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  // From the origin up +Y to (0,1,0), turned toward L = -X to (-1,1,0), then down to (-1,0,0).
  EXPECT_NE(r.out.find(": 11 modules, 0 chains, 0 segments, bbox [-1,0,0]..[0,1,0] m, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" ms, 1 leaf\n"), std::string::npos) << r.out;

  const std::string two = grammar("two.lsys", "angle: 90\nstep: 1\naxiom: F[{.f.+f.}][{.+f.+f.}]\n");
  r = run_sylva({"grow", two, "-o", dir_.file("two.skel.json")});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.out.find(" ms, 2 leaves\n"), std::string::npos) << r.out;

  r = run_sylva({"export", two, "-o", dir_.file("two.glb")});
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  EXPECT_NE(r.out.find(": 1 plant, 1 chains, 1 segments, 2 leaves, "), std::string::npos) << r.out;
}

TEST_F(CliTest, GrowRecordsSeedStepsAndDefinesInTheSkeletonSource) {
  const std::string g = grammar("g.lsys", "#define N 3\naxiom: F(N)\n");
  const std::string output = dir_.file("plant.skel.json");
  sylva_ok({"grow", g, "-o", output, "-n", "2", "--seed", "18446744073709551615", "-D", "N=5"});
  const std::string json = read_file(output);
  EXPECT_TRUE(std::regex_search(json, std::regex(R"("seed"\s*:\s*18446744073709551615\b)")))
      << "the 64-bit seed must be written exactly, never through a double\n" << json;
  EXPECT_TRUE(std::regex_search(json, std::regex(R"("steps"\s*:\s*2\b)"))) << json;
  EXPECT_TRUE(std::regex_search(json, std::regex(R"("N"\s*:\s*5\b)"))) << json;
}

TEST_F(CliTest, GrowingTwiceGivesByteIdenticalFiles) {
  const std::string g = grammar("tree.lsys",
                                "angle: 25.7\nseed: 3\nderivation length: 4\naxiom: F\n"
                                "F -> F[+F]F[-F]F : 0.33\nF -> F[+F]F : 0.33\nF -> F[-F]F : 0.34\n");
  const std::string first = dir_.file("first.skel.json"), second = dir_.file("second.skel.json");
  sylva_ok({"grow", g, "-o", first});
  sylva_ok({"grow", g, "-o", second});
  const std::string a = read_file(first), b = read_file(second);
  EXPECT_GT(a.size(), 200u);
  EXPECT_TRUE(a == b) << "two runs of the same command differ";
}

// ---------------------------------------------------------------------------------------
// Atomic output: a failed grow leaves an existing file as it was and no temporary files;
// a successful one replaces it.

class AtomicOutputTest : public CliTest {
 protected:
  void SetUp() override {
    fs::create_directory(dir_.path() / "out");
    output_ = (dir_.path() / "out" / "plant.skel.json").string();
    write_file(output_, kPrevious);
  }
  void expect_output_untouched() {
    EXPECT_EQ(read_file(output_), kPrevious) << "the existing output was changed";
    EXPECT_EQ(list_dir(dir_.path() / "out"), std::vector<std::string>{"plant.skel.json"})
        << "temporary files were left behind";
  }
  static constexpr const char* kPrevious = "previous contents, must survive a failed run\n";
  std::string output_;
};

TEST_F(AtomicOutputTest, FailedGrowOnBadGrammarLeavesExistingOutputUntouched) {
  ProcessResult r = run_sylva({"grow", grammar("bad.lsys", kBroken), "-o", output_});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  expect_output_untouched();
}

TEST_F(AtomicOutputTest, UsageErrorLeavesExistingOutputUntouched) {
  ProcessResult r = run_sylva({"grow", grammar("g.lsys", kBracketed), "-o", output_, "-n", "-1"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 2) << describe(r);
  expect_output_untouched();
}

TEST_F(AtomicOutputTest, SuccessfulGrowReplacesExistingOutput) {
  ProcessResult r = run_sylva({"grow", grammar("g.lsys", kBracketed), "-o", output_});
  ASSERT_FALSE(crashed(r)) << describe(r);
  ASSERT_EQ(r.exit_code, 0) << describe(r);
  const std::string json = read_file(output_);
  EXPECT_NE(json, kPrevious);
  EXPECT_NE(json.find("\"sylva-skeleton\""), std::string::npos) << json;
  EXPECT_EQ(list_dir(dir_.path() / "out"), std::vector<std::string>{"plant.skel.json"});
}

TEST_F(AtomicOutputTest, RunawayGrowthStopsAtDefaultMaxModulesWithBoundedMemory) {
  ProcessResult r = run_sylva({"grow", grammar("runaway.lsys", kRunaway), "-o", output_}, {}, 240);
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("max-modules"), std::string::npos) << describe(r);
  expect_output_untouched();
  if (kAddressSanitizer) {
    std::cout << "[   NOTE   ] AddressSanitizer build: peak memory " << r.max_rss_kb / 1024
              << " MiB not checked against the 2 GB bound\n";
  } else {
    EXPECT_LT(r.max_rss_kb, 2L * 1024 * 1024) << "peak memory must stay under 2 GB\n" << describe(r);
  }
}

TEST_F(AtomicOutputTest, RunawayGrowthWithSmallMaxModulesFailsFast) {
  ProcessResult r = run_sylva({"grow", grammar("runaway.lsys", kRunaway), "-o", output_, "--max-modules", "1000"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("max-modules"), std::string::npos) << describe(r);
  EXPECT_LT(r.wall_s, 10.0) << "1000 modules are reached after 10 steps; stopping must be immediate";
  expect_output_untouched();
}

TEST_F(CliTest, DeriveStopsAtMaxModulesAndPrintsNoWord) {
  ProcessResult r = run_sylva({"derive", grammar("runaway.lsys", kRunaway), "--max-modules", "1000"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("max-modules"), std::string::npos) << describe(r);
  EXPECT_EQ(r.out, "") << "no partial word";
  EXPECT_LT(r.wall_s, 10.0);
}

TEST_F(CliTest, MaxModulesIsAnInclusiveBound) {
  // A -> AA three times gives exactly 8 modules: allowed at 8, refused at 7.
  const std::string g = grammar("g.lsys", "axiom: A\nA -> AA\n");
  EXPECT_EQ(derive({g, "-n", "3", "--max-modules", "8"}), "AAAAAAAA\n");
  ProcessResult r = run_sylva({"derive", g, "-n", "3", "--max-modules", "7"});
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << describe(r);
  EXPECT_NE(r.err.find("max-modules"), std::string::npos) << describe(r);
}

}  // namespace
