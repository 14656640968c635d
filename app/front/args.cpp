// args.cpp — the flag parser and the grammar flags of args.h.
#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>

#include "app/front/args.h"

namespace sylva::cli {

std::optional<uint64_t> parse_u64(const std::string& text) {
  if (text.empty() || text[0] == '-' || text[0] == '+') return std::nullopt;
  uint64_t v = 0;
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || ptr != text.data() + text.size()) return std::nullopt;
  return v;
}

uint32_t parse_count(const std::string& flag, const std::string& value, uint64_t max) {
  auto n = parse_u64(value);
  if (!n || *n == 0 || *n > max)
    throw UsageError{flag + " " + value + ": expected an integer from 1 to " + std::to_string(max)};
  return static_cast<uint32_t>(*n);
}

Flag switch_flag(std::vector<std::string> names, std::function<void()> action) {
  Flag flag;
  flag.names = std::move(names);
  flag.apply = [action = std::move(action)](const std::string&, const std::string&) { action(); };
  return flag;
}

Flag set_flag(std::vector<std::string> names, bool& on) {
  return switch_flag(std::move(names), [&on] { on = true; });
}

Flag help_flag(bool& help) { return set_flag({"-h", "--help"}, help); }

Flag help_at_once(bool& help) {
  Flag flag = help_flag(help);
  flag.ends_parsing = true;
  return flag;
}

Flag value_flag(std::vector<std::string> names,
                std::function<void(const std::string& spelled, const std::string& value)> apply) {
  Flag flag;
  flag.names = std::move(names);
  flag.takes_value = true;
  flag.apply = std::move(apply);
  return flag;
}

Flag text_flag(std::vector<std::string> names, std::string& text) {
  return value_flag(std::move(names), [&text](const std::string&, const std::string& value) { text = value; });
}

Flag skin_flag(std::optional<SkinStyle>& style) {
  return value_flag({"--skin"}, [&style](const std::string& spelled, const std::string& value) {
    style = parse_skin_style(value);
    if (!style) throw UsageError{spelled + " " + value + ": expected smooth or paper"};
  });
}

Flag noting_given(Flag flag, bool& given) {
  flag.apply = [&given, apply = std::move(flag.apply)](const std::string& spelled, const std::string& value) {
    apply(spelled, value);
    given = true;
  };
  return flag;
}

namespace {

// The flag of `table` spelled `name`, or null.
const Flag* flag_named(const FlagTable& table, const std::string& name) {
  for (const Flag& flag : table.flags)
    if (std::ranges::find(flag.names, name) != flag.names.end()) return &flag;
  return nullptr;
}

// An argument read as one of the table's flags: which, spelled how, with any value it holds.
struct FlagArg {
  const Flag* flag = nullptr;               // null: not a flag of the table
  std::string spelled;                      // "--width" of "--width=5", "-n" of "-n5"
  std::optional<std::string> inline_value;  // "5" of both
};

FlagArg read_flag(const std::string& arg, const FlagTable& table) {
  const size_t equals = arg.find('=');
  if (table.inline_values != InlineValues::none && arg.starts_with("--") && equals != std::string::npos) {
    std::string name = arg.substr(0, equals);
    const Flag* flag = flag_named(table, name);
    if (flag && (flag->takes_value || table.inline_values == InlineValues::all_flags))
      return {flag, std::move(name), arg.substr(equals + 1)};
    return {};
  }
  if (const Flag* flag = flag_named(table, arg)) return {flag, arg, std::nullopt};
  // A one-letter flag with its value attached: "-n5", "-DN=1".
  if (arg.size() > 2 && arg[0] == '-' && arg[1] != '-')
    if (const Flag* flag = flag_named(table, arg.substr(0, 2)); flag && flag->takes_value)
      return {flag, arg.substr(0, 2), arg.substr(2)};
  return {};
}

}  // namespace

std::vector<std::string> parse_flags(std::span<const std::string> args, const FlagTable& table) {
  std::vector<std::string> left;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    FlagArg given = read_flag(arg, table);
    if (given.flag && given.flag->takes_value) {
      std::optional<std::string> value = given.inline_value;
      const bool value_follows = !value && i + 1 < args.size();
      if (value_follows) value = args[i + 1];
      if (given.flag->claims && !(value && given.flag->claims(*value))) {
        given.flag = nullptr;  // not this flag after all: an unknown option, below
      } else {
        if (!value) throw UsageError{given.spelled + " needs a value"};
        if (value_follows) ++i;
        given.flag->apply(given.spelled, *value);
      }
    } else if (given.flag) {
      given.flag->apply(given.spelled, "");
    }
    if (given.flag) {
      if (given.flag->ends_parsing) break;
      continue;
    }
    const bool is_option = !arg.empty() && arg[0] == '-' && !(arg == "-" && table.dash_is_positional);
    if (table.leaves_others) {
      left.push_back(arg);
      if (i + 1 < args.size() && std::ranges::find(table.later_value_flags, arg) != table.later_value_flags.end())
        left.push_back(args[++i]);
    } else if (!is_option && table.positional) {
      table.positional(arg);
    } else if (table.unknown) {
      table.unknown(arg);
    } else {
      throw UsageError{"unknown option '" + arg + "'"};
    }
  }
  return left;
}

namespace {

double parse_define_value(const std::string& name, const std::string& text) {
  double v = 0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+') ++first;
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (text.empty() || ec != std::errc() || ptr != last || !std::isfinite(v))
    throw UsageError{"-D " + name + "=" + text + ": the value must be a finite number"};
  return v;
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// The grammar flags, filling `out`.
FlagTable grammar_flag_table(GrammarArgs& out, const GrammarArgsOptions& options) {
  FlagTable table;
  table.inline_values = InlineValues::all_flags;
  table.dash_is_positional = true;
  table.flags = {
      help_flag(out.help),
      value_flag({"-n", "--steps"},
                 [&out](const std::string& spelled, const std::string& v) {
                   auto n = parse_u64(v);
                   if (!n || *n > 1000000)
                     throw UsageError{spelled + " " + v +
                                      ": the number of steps must be an integer from 0 to 1000000"};
                   out.steps = static_cast<int64_t>(*n);
                 }),
      value_flag({"--seed"},
                 [&out](const std::string&, const std::string& v) {
                   auto s = parse_u64(v);
                   if (!s)
                     throw UsageError{"--seed " + v + ": the seed must be an integer from 0 to 18446744073709551615"};
                   out.seed = *s;
                 }),
      value_flag({"-D", "--define"},
                 [&out](const std::string&, const std::string& v) {
                   size_t eq = v.find('=');
                   if (eq == std::string::npos) throw UsageError{"-D " + v + ": expected NAME=VALUE"};
                   std::string name = v.substr(0, eq);
                   if (!is_identifier(name)) throw UsageError{"-D " + v + ": '" + name + "' is not a valid name"};
                   out.defines[name] = parse_define_value(name, v.substr(eq + 1));
                 }),
      value_flag({"--max-modules"},
                 [&out](const std::string&, const std::string& v) {
                   auto n = parse_u64(v);
                   if (!n || *n == 0 || *n > 0xFFFFFFF0u)
                     throw UsageError{"--max-modules " + v + ": expected an integer from 1 to 4294967280"};
                   out.max_modules = *n;
                 }),
  };
  if (options.wants_output)
    table.flags.push_back(value_flag({"-o", "--output"}, [&out](const std::string&, const std::string& v) {
      out.output = v;
      if (out.output.empty()) throw UsageError{"-o needs a file name"};
    }));
  table.positional = [&out, input_name = options.input_name](const std::string& arg) {
    if (!out.grammar.empty()) throw UsageError{"unexpected argument '" + arg + "' (one " + input_name + " only)"};
    out.grammar = arg;
  };
  return table;
}

}  // namespace

const std::vector<std::string>& grammar_value_flags() {
  static const std::vector<std::string> names = [] {
    GrammarArgs unused;
    std::vector<std::string> value_flags;
    for (const Flag& flag : grammar_flag_table(unused, {.wants_output = true}).flags)
      if (flag.takes_value) value_flags.insert(value_flags.end(), flag.names.begin(), flag.names.end());
    return value_flags;
  }();
  return names;
}

GrammarArgs parse_grammar_args(std::span<const std::string> args, const GrammarArgsOptions& options) {
  GrammarArgs out;
  parse_flags(args, grammar_flag_table(out, options));
  if (out.help) return out;
  if (out.grammar.empty()) throw UsageError{options.missing_input};
  if (options.wants_output && out.output.empty()) throw UsageError{options.missing_output};
  return out;
}

}  // namespace sylva::cli
