// args_test.cpp — the flag parser of app/front/args.h that every subcommand reads its
// arguments with: values, inline values, unknown options, positionals, arguments left for
// a later parser, and the grammar flags' seed ranges (app/front/batch.h) built on it.
#include "app/front/args.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/front/batch.h"

namespace sylva::cli {
namespace {

using Args = std::vector<std::string>;

// The UsageError message parse_flags throws for `args`, or "" when it throws none.
std::string usage_error(const Args& args, const FlagTable& table) {
  try {
    parse_flags(args, table);
  } catch (const UsageError& e) {
    return e.message;
  }
  return "";
}

TEST(ParseFlags, AValueIsTheNextArgumentWhateverItLooksLike) {
  std::string csv, input;
  bool quick = false;
  FlagTable table;
  table.flags = {text_flag({"--csv"}, csv), set_flag({"--quick"}, quick)};
  table.positional = [&](const std::string& arg) { input = arg; };
  parse_flags(Args{"--csv", "--quick", "in.lsys"}, table);
  EXPECT_EQ(csv, "--quick");
  EXPECT_FALSE(quick);
  EXPECT_EQ(input, "in.lsys");
}

TEST(ParseFlags, AValueFlagGivenLastNeedsAValueNamedAsSpelled) {
  uint32_t steps = 0;
  FlagTable table;
  table.flags = {count_flag({"-n", "--steps"}, steps, 10)};
  EXPECT_EQ(usage_error({"-n"}, table), "-n needs a value");
  EXPECT_EQ(usage_error({"--steps"}, table), "--steps needs a value");
  EXPECT_EQ(usage_error({"--steps", "11"}, table), "--steps 11: expected an integer from 1 to 10");
  parse_flags(Args{"-n7"}, table);  // a one-letter flag may hold its value
  EXPECT_EQ(steps, 7u);
}

TEST(ParseFlags, InlineValuesFollowTheTable) {
  std::string csv;
  bool quick = false;
  FlagTable table;
  table.flags = {text_flag({"--csv"}, csv), set_flag({"--quick"}, quick)};

  table.inline_values = InlineValues::none;
  EXPECT_EQ(usage_error({"--csv=a.csv"}, table), "unknown option '--csv=a.csv'");

  table.inline_values = InlineValues::value_flags;
  parse_flags(Args{"--csv=a.csv"}, table);
  EXPECT_EQ(csv, "a.csv");
  parse_flags(Args{"--csv="}, table);  // an empty inline value is a value
  EXPECT_EQ(csv, "");
  EXPECT_EQ(usage_error({"--quick=1"}, table), "unknown option '--quick=1'");

  table.inline_values = InlineValues::all_flags;
  parse_flags(Args{"--quick=1"}, table);
  EXPECT_TRUE(quick);
}

TEST(ParseFlags, UnknownOptionsAndPositionals) {
  std::vector<std::string> positionals, unknown;
  FlagTable table;
  EXPECT_EQ(usage_error({"--bogus"}, table), "unknown option '--bogus'");
  EXPECT_EQ(usage_error({"in.lsys"}, table), "unknown option 'in.lsys'");  // no positional wanted
  table.positional = [&](const std::string& arg) { positionals.push_back(arg); };
  EXPECT_EQ(usage_error({"-"}, table), "unknown option '-'");
  table.dash_is_positional = true;
  table.unknown = [&](const std::string& arg) { unknown.push_back(arg); };
  parse_flags(Args{"-", "", "--x=1", "a"}, table);
  EXPECT_EQ(positionals, (Args{"-", "", "a"}));
  EXPECT_EQ(unknown, (Args{"--x=1"}));
}

TEST(ParseFlags, LeavesOthersInOrderWithTheLaterParsersValues) {
  uint32_t width = 0;
  FlagTable table;
  table.flags = {count_flag({"--width"}, width, 100)};
  table.leaves_others = true;
  table.later_value_flags = {"-o"};
  EXPECT_EQ(parse_flags(Args{"in.lsys", "-o", "--width", "--bogus", "--width", "5", "-n3"}, table),
            (Args{"in.lsys", "-o", "--width", "--bogus", "-n3"}));
  EXPECT_EQ(width, 5u);
}

TEST(ParseFlags, AClaimingFlagLeavesTheValuesItRefuses) {
  std::vector<std::string> ranges;
  Flag range = value_flag({"--seed"}, [&](const std::string&, const std::string& v) { ranges.push_back(v); });
  range.claims = [](const std::string& v) { return v.find("..") != std::string::npos; };
  FlagTable table;
  table.flags = {range};
  table.inline_values = InlineValues::value_flags;
  table.leaves_others = true;
  table.later_value_flags = {"--seed"};
  EXPECT_EQ(parse_flags(Args{"--seed", "3", "--seed=1..2", "--seed=4", "--seed", "5..6", "--seed"}, table),
            (Args{"--seed", "3", "--seed=4", "--seed"}));
  EXPECT_EQ(ranges, (Args{"1..2", "5..6"}));
}

TEST(ParseFlags, AFlagThatEndsParsingLeavesTheRestUnread) {
  bool help = false;
  FlagTable table;
  table.flags = {help_at_once(help)};
  EXPECT_EQ(usage_error({"--bogus", "-h"}, table), "unknown option '--bogus'");
  EXPECT_EQ(usage_error({"-h", "--bogus"}, table), "");
  EXPECT_TRUE(help);
}

TEST(ParseFlags, NotingGivenSaysWhetherTheFlagWasGiven) {
  std::optional<uint32_t> width;
  bool given = false;
  FlagTable table;
  table.flags = {noting_given(count_flag({"--width"}, width, 100), given)};
  parse_flags(Args{}, table);
  EXPECT_FALSE(given);
  parse_flags(Args{"--width", "9"}, table);
  EXPECT_TRUE(given);
  EXPECT_EQ(width, 9u);
}

TEST(GrammarArgs, ValueFlagsAreTheGrammarTablesOwn) {
  EXPECT_EQ(grammar_value_flags(),
            (Args{"-n", "--steps", "--seed", "-D", "--define", "--max-modules", "-o", "--output"}));
}

TEST(GrammarArgs, SpellingsAndMessages) {
  const GrammarArgs a = parse_grammar_args(Args{"-n3", "--seed=9", "-DN=1", "--define", "M=+2", "g.lsys", "-oout"},
                                           {.wants_output = true});
  EXPECT_EQ(a.steps, 3);
  EXPECT_EQ(a.seed, 9u);
  EXPECT_EQ(a.defines, (std::map<std::string, double>{{"N", 1}, {"M", 2}}));
  EXPECT_EQ(a.grammar, "g.lsys");
  EXPECT_EQ(a.output, "out");
  auto message = [](const Args& args, const GrammarArgsOptions& options) {
    try {
      parse_grammar_args(args, options);
    } catch (const UsageError& e) {
      return e.message;
    }
    return std::string();
  };
  EXPECT_EQ(message({"a", "b"}, {}), "unexpected argument 'b' (one GRAMMAR only)");
  EXPECT_EQ(message({"a", "b"}, {.input_name = "INPUT"}), "unexpected argument 'b' (one INPUT only)");
  EXPECT_EQ(message({}, {.missing_input = "missing INPUT"}), "missing INPUT");
  EXPECT_EQ(message({"a"}, {.wants_output = true}), "missing -o FILE.skel.json");
  EXPECT_EQ(message({"a", "-ox"}, {}), "unknown option '-ox'");  // -o only where an output is wanted
  EXPECT_EQ(message({"--help", "-n", "x"}, {}), "-n x: the number of steps must be an integer from 0 to 1000000");
  EXPECT_EQ(message({"--help=1"}, {}), "");
}

TEST(SeedRange, IsTakenOutAndASingleSeedLeftForTheGrammarFlags) {
  Args args = {"g.lsys", "-o", "o_{seed}.skel.json", "--seed=1..3", "-n", "2"};
  const std::optional<SeedRange> range = take_seed_range(args, grammar_value_flags());
  ASSERT_TRUE(range);
  EXPECT_EQ(range->first, 1u);
  EXPECT_EQ(range->last, 3u);
  EXPECT_EQ(args, (Args{"g.lsys", "-o", "o_{seed}.skel.json", "-n", "2"}));

  Args single = {"g.lsys", "--seed", "4"};
  EXPECT_FALSE(take_seed_range(single, grammar_value_flags()));
  EXPECT_EQ(single, (Args{"g.lsys", "--seed", "4"}));

  Args value_of_d = {"g.lsys", "-D", "--seed=1..2"};  // -D's value, not a range
  EXPECT_FALSE(take_seed_range(value_of_d, grammar_value_flags()));
  EXPECT_EQ(value_of_d, (Args{"g.lsys", "-D", "--seed=1..2"}));

  Args twice = {"--seed", "4", "--seed", "1..2"};
  try {
    take_seed_range(twice, grammar_value_flags());
    ADD_FAILURE() << "a range and a seed must be a usage error";
  } catch (const UsageError& e) {
    EXPECT_EQ(e.message, "--seed given twice");
  }
}

}  // namespace
}  // namespace sylva::cli
