// args.cpp — flag parsing shared by the subcommands (args.h).
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

}  // namespace

GrammarArgs parse_grammar_args(const std::vector<std::string>& args, bool wants_output) {
  GrammarArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string a = args[i];
    std::string inline_value;
    bool has_inline = false;
    if (a.rfind("--", 0) == 0 && a.find('=') != std::string::npos) {
      inline_value = a.substr(a.find('=') + 1);
      a = a.substr(0, a.find('='));
      has_inline = true;
    } else if (a.size() > 2 && a[0] == '-' && a[1] != '-' && (a[1] == 'D' || a[1] == 'n' || a[1] == 'o')) {
      inline_value = a.substr(2);
      a = a.substr(0, 2);
      has_inline = true;
    }
    auto value = [&]() -> std::string {
      if (has_inline) return inline_value;
      if (i + 1 >= args.size()) throw UsageError{a + " needs a value"};
      return args[++i];
    };
    if (a == "-h" || a == "--help") {
      out.help = true;
    } else if (a == "-n" || a == "--steps") {
      std::string v = value();
      auto n = parse_u64(v);
      if (!n || *n > 1000000) throw UsageError{a + " " + v + ": the number of steps must be an integer from 0 to 1000000"};
      out.steps = static_cast<int64_t>(*n);
    } else if (a == "--seed") {
      std::string v = value();
      auto s = parse_u64(v);
      if (!s) throw UsageError{"--seed " + v + ": the seed must be an integer from 0 to 18446744073709551615"};
      out.seed = *s;
    } else if (a == "-D" || a == "--define") {
      std::string v = value();
      size_t eq = v.find('=');
      if (eq == std::string::npos) throw UsageError{"-D " + v + ": expected NAME=VALUE"};
      std::string name = v.substr(0, eq);
      if (!is_identifier(name)) throw UsageError{"-D " + v + ": '" + name + "' is not a valid name"};
      out.defines[name] = parse_define_value(name, v.substr(eq + 1));
    } else if (a == "--max-modules") {
      std::string v = value();
      auto n = parse_u64(v);
      if (!n || *n == 0 || *n > 0xFFFFFFF0u) throw UsageError{"--max-modules " + v + ": expected an integer from 1 to 4294967280"};
      out.max_modules = *n;
    } else if (wants_output && (a == "-o" || a == "--output")) {
      out.output = value();
      if (out.output.empty()) throw UsageError{"-o needs a file name"};
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      throw UsageError{"unknown option '" + args[i] + "'"};
    } else {
      if (!out.grammar.empty()) throw UsageError{"unexpected argument '" + a + "' (one GRAMMAR only)"};
      out.grammar = a;
    }
  }
  if (out.help) return out;
  if (out.grammar.empty()) throw UsageError{"missing GRAMMAR (a .lsys file)"};
  if (wants_output && out.output.empty()) throw UsageError{"missing -o FILE.skel.json"};
  return out;
}

}  // namespace sylva::cli
