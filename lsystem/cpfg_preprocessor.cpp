// cpfg_preprocessor.cpp — the C preprocessor of cpfg model files (see cpfg_preprocessor.h).
#include "lsystem/cpfg_preprocessor.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <memory>
#include <unordered_map>

#include "core/util/file_io.h"
#include "lsystem/word.h"

namespace sylva::lsys {

namespace {

using namespace detail;  // NOLINT: this file is part of the detail it implements

constexpr int kMaxIncludeDepth = 16;
constexpr int kMaxMacroDepth = 256;
constexpr size_t kMaxExpansionBytes = size_t{1} << 20;
constexpr int kMaxIfNesting = 256;

// Replaces `/* */` and `//` comments by spaces, outside "strings", keeping newlines. As in
// cpp a comment is one space, so a line that a `/* */` comment runs across continues after
// it: `joined[k]` is set for each line k (0-based) whose newline lies inside a comment.
std::string blank_comments(std::string_view text, uint32_t file, std::vector<uint8_t>& joined) {
  std::string out(text);
  uint32_t line = 1, col = 1;
  bool in_string = false;
  auto advance = [&](char c) {
    if (c == '\n') ++line, col = 1;
    else ++col;
  };
  for (size_t i = 0; i < out.size(); ++i) {
    const char c = out[i];
    if (in_string) {
      if (c == '\\' && i + 1 < out.size() && out[i + 1] != '\n') advance(out[i++]);
      else if (c == '"' || c == '\n') in_string = false;
      advance(out[i]);
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '/' && i + 1 < out.size() && out[i + 1] == '*') {
      const SourceLoc start{line, col, file};
      const size_t end = out.find("*/", i + 2);
      if (end == std::string::npos) fail(start, "unterminated comment: '/*' has no '*/'");
      for (size_t k = i; k < end + 2; ++k) {
        if (out[k] == '\n') {
          if (joined.size() < line) joined.resize(line, 0);
          joined[line - 1] = 1;
        }
        advance(out[k]);
        if (out[k] != '\n') out[k] = ' ';
      }
      i = end + 1;
      continue;
    } else if (c == '/' && i + 1 < out.size() && out[i + 1] == '/') {
      while (i < out.size() && out[i] != '\n') out[i++] = ' ', ++col;
      if (i < out.size()) advance(out[i]);
      continue;
    }
    advance(c);
  }
  return out;
}

// The file's lines, those ending in `\` or inside a comment (`joined`) joined to the next.
std::vector<LogicalLine> physical_to_logical(const std::string& text, uint32_t file, const std::vector<uint8_t>& joined) {
  std::vector<LogicalLine> lines;
  LogicalLine current;
  for_each_physical_line(text, [&](uint32_t line_no, std::string_view phys, bool last) {
    size_t keep = phys.size();
    while (keep > 0 && is_space(phys[keep - 1])) --keep;
    const bool backslash = keep > 0 && phys[keep - 1] == '\\' && !last;
    const bool in_comment = line_no <= joined.size() && joined[line_no - 1] && !last;
    current.pieces.push_back({current.text.size(), line_no, 1, file});
    // A doubled backslash before the newline (`#define f(x) \\`, as vlab's models write
    // it) joins too; cpp would leave the first one, which cpfg's reader skips.
    size_t cut = backslash ? keep - 1 : phys.size();
    if (backslash && cut > 0 && phys[cut - 1] == '\\') --cut;
    current.text.append(phys.substr(0, cut));
    if (in_comment) current.text += ' ';
    if (!backslash && !in_comment) {
      lines.push_back(std::move(current));
      current = LogicalLine{};
    }
  });
  return lines;
}

// Appends in.text[a, b) to out with its places.
void append_source(LogicalLine& out, const LogicalLine& in, size_t a, size_t b) {
  if (a >= b) return;
  size_t p = a;
  while (p < b) {
    const SourceLoc loc = in.loc(p);
    size_t piece_end = b;  // the end of the input piece that holds p
    for (const LogicalLine::Piece& piece : in.pieces)
      if (piece.offset > p) {
        piece_end = std::min(piece_end, piece.offset);
        break;
      }
    out.pieces.push_back({out.text.size(), loc.line, loc.column, loc.file});
    out.text.append(in.text, p, piece_end - p);
    p = piece_end;
  }
}

struct Macro {
  bool function_like = false;
  bool predefined = false;  // ParseOptions::predefined_macros: a #define may replace it
  std::vector<std::string> params;
  std::string body;
  SourceLoc loc;
};

class Preprocessor {
 public:
  Preprocessor(const std::string& file, const ParseOptions& options, std::vector<IncludedFile>& includes)
      : options_(options), main_file_(file), includes_(includes) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path folder = fs::path(file).parent_path();
    folder_ = fs::weakly_canonical(folder.empty() ? fs::path(".") : folder, ec);
    if (ec) folder_ = folder;
  }

  detail::CpfgSource run(std::string_view text) {
    std::error_code ec;
    std::filesystem::path main = std::filesystem::weakly_canonical(main_file_, ec);
    if (ec) main.clear();
    for (const auto& [name, body] : options_.predefined_macros) {
      Macro m;
      m.body = body;
      m.predefined = true;
      macros_[name] = std::move(m);
    }
    process(text, 0, main);
    for (const auto& [name, value] : options_.define_overrides)
      if (!overridable_.count(name)) fail({0, 0}, "-D " + name + ": the grammar has no '#define " + name + " <number>'");
    return std::move(out_);
  }

 private:
  // ---- files and directives ----
  void process(std::string_view text, uint32_t file, const std::filesystem::path& canonical) {
    if (!canonical.empty()) open_files_.push_back(canonical);
    std::vector<uint8_t> joined;
    const std::string clean = blank_comments(text, file, joined);
    const size_t conditions_before = conditions_.size();
    // Whether the line cpp would write before this one is blank (a directive, a line of a
    // group left out and a blank line are; a file's first line follows a line marker).
    bool after_blank = true;
    for (const LogicalLine& line : physical_to_logical(clean, file, joined)) {
      size_t i = 0;
      while (i < line.text.size() && is_space(line.text[i])) ++i;
      // A `#` followed by a name (or nothing: the null directive) starts a directive; one
      // followed by anything else is the model's line-width module at the start of a line
      // (`\t#(0.06) f(0.1)`, a successor going on), which cpfg's preprocessing keeps.
      size_t after_hash = i + 1;
      while (after_hash < line.text.size() && is_space(line.text[after_hash])) ++after_hash;
      const bool directive_line = i < line.text.size() && line.text[i] == '#' &&
                                  (after_hash == line.text.size() || is_ident_start(line.text[after_hash]));
      if (directive_line) {
        directive(line, i + 1);
        after_blank = true;
        continue;
      }
      if (!active()) {
        after_blank = true;
        continue;
      }
      LogicalLine expanded;
      expand_line(line, expanded);
      bool blank = true;
      for (char c : expanded.text) blank = blank && is_space(c);
      expanded.continues_previous = !blank && !after_blank && !line.text.empty() && line.text[0] == '\t';
      after_blank = blank;
      if (!blank) out_.lines.push_back(std::move(expanded));
    }
    if (conditions_.size() > conditions_before)
      fail(conditions_.back().loc, "'#" + conditions_.back().name + "' has no '#endif' in its file");
    if (!canonical.empty()) open_files_.pop_back();
  }

  struct Condition {
    bool outer_active;  // the lines around the #if are read
    bool taking;        // this branch's lines are read
    bool taken;         // some branch was taken
    bool seen_else;
    SourceLoc loc;
    std::string name;
  };
  bool active() const { return conditions_.empty() || conditions_.back().taking; }

  void directive(const LogicalLine& line, size_t p) {
    while (p < line.text.size() && is_space(line.text[p])) ++p;
    const size_t name_start = p;
    while (p < line.text.size() && is_ident_char(line.text[p])) ++p;
    const std::string name = line.text.substr(name_start, p - name_start);
    const SourceLoc loc = line.loc(name_start == p ? name_start - 1 : name_start);
    size_t rest = p;
    while (rest < line.text.size() && is_space(line.text[rest])) ++rest;
    size_t end = line.text.size();
    while (end > rest && is_space(line.text[end - 1])) --end;
    const std::string_view value(line.text.data() + rest, end - rest);
    if (name == "if" || name == "ifdef" || name == "ifndef") {
      if (conditions_.size() >= kMaxIfNesting) fail(loc, "conditionals nested too deeply (more than 256)");
      bool yes = false;
      if (active()) {
        if (name == "if") yes = evaluate_condition(line, rest, end, loc) != 0;
        else yes = (macros_.count(identifier(value, loc, name)) != 0) == (name == "ifdef");
      }
      conditions_.push_back({active(), active() && yes, yes, false, loc, name});
      return;
    }
    if (name == "elif" || name == "else" || name == "endif") {
      if (conditions_.empty()) fail(loc, "'#" + name + "' without '#if'");
      Condition& c = conditions_.back();
      if (name == "endif") {
        conditions_.pop_back();
        return;
      }
      if (c.seen_else) fail(loc, "'#" + name + "' after '#else'");
      if (name == "else") {
        c.seen_else = true;
        c.taking = c.outer_active && !c.taken;
      } else {
        const bool yes = c.outer_active && !c.taken && evaluate_condition(line, rest, end, loc) != 0;
        c.taking = yes;
      }
      c.taken = c.taken || c.taking;
      return;
    }
    if (!active()) return;  // other directives in a skipped branch are not read
    if (name == "define") return define(line, rest, end, loc);
    if (name == "undef") {
      macros_.erase(identifier(value, loc, name));
      return;
    }
    if (name == "include") return include(value, line.loc(rest));
    if (name == "error") fail(loc, "#error " + std::string(value));
    if (name == "pragma" || name.empty()) return;  // read and ignored; '#' alone is the null directive
    fail(loc, "unknown preprocessor directive '#" + name + "'");
  }

  static std::string identifier(std::string_view value, SourceLoc loc, const std::string& directive) {
    size_t n = 0;
    while (n < value.size() && is_ident_char(value[n])) ++n;
    if (n == 0 || !is_ident_start(value[0])) fail(loc, "#" + directive + " needs a macro name");
    return std::string(value.substr(0, n));
  }

  void define(const LogicalLine& line, size_t p, size_t end, SourceLoc directive_loc) {
    const std::string& t = line.text;
    const SourceLoc loc = line.loc(p);
    if (p >= end || !is_ident_start(t[p])) fail(p < end ? loc : directive_loc, "#define needs a name: '#define NAME value'");
    const size_t name_start = p;
    while (p < end && is_ident_char(t[p])) ++p;
    const std::string name = t.substr(name_start, p - name_start);
    Macro m;
    m.loc = loc;
    if (p < end && t[p] == '(') {  // function-like: '(' right after the name
      m.function_like = true;
      ++p;
      for (;;) {
        while (p < end && is_space(t[p])) ++p;
        if (p < end && t[p] == ')' && m.params.empty()) break;
        const size_t s = p;
        while (p < end && is_ident_char(t[p])) ++p;
        if (s == p || !is_ident_start(t[s])) fail(line.loc(s), "expected a parameter name in the '#define " + name + "(...)'");
        m.params.push_back(t.substr(s, p - s));
        while (p < end && is_space(t[p])) ++p;
        if (p < end && t[p] == ',') {
          ++p;
          continue;
        }
        if (p < end && t[p] == ')') break;
        fail(line.loc(p), "expected ',' or ')' in the parameters of '#define " + name + "'");
      }
      ++p;
    }
    while (p < end && is_space(t[p])) ++p;
    m.body = t.substr(p, end - p);
    if (auto it = macros_.find(name);
        it != macros_.end() && !it->second.predefined && (it->second.body != m.body || it->second.params != m.params))
      fail(loc, "'" + name + "' is defined twice (first at line " + std::to_string(it->second.loc.line) + ")");
    if (!m.function_like) number_define(name, m, line.loc(p));
    macros_[name] = std::move(m);
  }

  // An object-like define whose value is one number: a Define (-D and the studio's sliders).
  void number_define(const std::string& name, Macro& m, SourceLoc value_loc) {
    std::string_view body = m.body;
    double value = 0;
    const char* first = body.data();
    const char* last = body.data() + body.size();
    const bool negative = !body.empty() && body[0] == '-';
    auto [ptr, ec] = std::from_chars(first + (negative ? 1 : 0), last, value);
    if (body.empty() || ec != std::errc() || ptr != last || !std::isfinite(value)) return;
    if (negative) value = -value;
    for (const Define& d : out_.defines)
      if (d.name == name) return;  // an identical redefinition
    Define d{name, value, value_loc, false};
    if (auto ov = options_.define_overrides.find(name); ov != options_.define_overrides.end()) {
      d.value = ov->second;
      d.overridden = true;
      m.body.clear();
      append_shortest_double(m.body, d.value);
      if (d.value < 0) m.body = "(" + m.body + ")";
    }
    overridable_.emplace(name, true);
    out_.defines.push_back(d);
  }

  void include(std::string_view value, SourceLoc loc) {
    namespace fs = std::filesystem;
    if (value.size() < 2 || !((value.front() == '"' && value.back() == '"') || (value.front() == '<' && value.back() == '>')))
      fail(loc, "#include needs a file name in quotes: #include \"file\"");
    const std::string name(value.substr(1, value.size() - 2));
    const fs::path relative(name);
    if (name.empty() || relative.is_absolute())
      fail(loc, "#include \"" + name + "\": only a file in the model's folder can be included");
    for (const fs::path& part : relative)
      if (part == "..") fail(loc, "#include \"" + name + "\": only a file in the model's folder can be included ('..' leaves it)");
    if (open_files_.size() >= static_cast<size_t>(kMaxIncludeDepth))
      fail(loc, "#include nested too deeply (more than 16 files)");
    std::error_code ec;
    const fs::path path = folder_ / relative;
    const fs::path canonical = fs::weakly_canonical(path, ec);
    if (ec) fail(loc, "#include \"" + name + "\": " + ec.message());
    auto [stop, _] = std::mismatch(folder_.begin(), folder_.end(), canonical.begin(), canonical.end());
    if (stop != folder_.end())
      fail(loc, "#include \"" + name + "\": the file lies outside the model's folder (through a link)");
    for (const fs::path& open : open_files_)
      if (open == canonical) fail(loc, "#include \"" + name + "\" includes itself (recursive #include)");
    Expected<std::string> text = read_text_file(path.string());
    if (!text) fail(loc, "#include \"" + name + "\": " + text.error().message);
    auto shared = std::make_shared<const std::string>(std::move(*text));
    includes_.push_back(IncludedFile{path.string(), shared, loc});
    const uint32_t index = static_cast<uint32_t>(includes_.size());
    detail::validate_text(*shared, index);
    std::string_view body = *shared;
    if (body.substr(0, 3) == "\xEF\xBB\xBF") body.remove_prefix(3);  // a BOM, read and skipped
    process(body, index, canonical);
  }

  // ---- macro expansion ----
  // Expands the macros of `text` with `hidden` not expanded (those being expanded).
  std::string expand_text(std::string_view text, std::vector<std::string>& hidden, SourceLoc loc, int depth) {
    if (depth > kMaxMacroDepth) fail(loc, "macros nested too deeply (more than 256)");
    std::string out;
    size_t i = 0;
    while (i < text.size()) {
      const char c = text[i];
      if (c == '"') {  // a string: copied as written
        size_t j = i + 1;
        while (j < text.size() && text[j] != '"') j += text[j] == '\\' ? 2 : 1;
        j = std::min(j + 1, text.size());
        out.append(text, i, j - i);
        i = j;
        continue;
      }
      if (!is_ident_start(c) || (i > 0 && (is_ident_char(text[i - 1]) || text[i - 1] == '.'))) {
        out += c;
        ++i;
        continue;
      }
      size_t j = i;
      while (j < text.size() && is_ident_char(text[j])) ++j;
      const std::string name(text.substr(i, j - i));
      size_t after = j;
      std::string replacement;
      if (expand_name(name, text, &after, hidden, loc, depth, &replacement)) {
        out += replacement;
        i = after;
      } else {
        out += name;
        i = j;
      }
      if (out.size() > kMaxExpansionBytes) fail(loc, "macro expansion too large (more than 1 MiB)");
    }
    return out;
  }

  // If `name` (ending at *after in text) is a macro to expand there, sets *replacement and
  // moves *after past its arguments.
  bool expand_name(const std::string& name, std::string_view text, size_t* after, std::vector<std::string>& hidden,
                   SourceLoc loc, int depth, std::string* replacement) {
    auto it = macros_.find(name);
    if (it == macros_.end() || std::find(hidden.begin(), hidden.end(), name) != hidden.end()) return false;
    const Macro& m = it->second;
    std::string body = m.body;
    if (m.function_like) {
      size_t p = *after;
      while (p < text.size() && is_space(text[p])) ++p;
      if (p >= text.size() || text[p] != '(') return false;  // the name alone: not a call
      std::vector<std::string> args;
      int nesting = 0;
      size_t start = ++p;
      for (;; ++p) {
        if (p >= text.size()) fail(loc, "the arguments of macro '" + name + "' are not closed on this line");
        const char ch = text[p];
        if (ch == '(') ++nesting;
        else if (ch == ')' && nesting > 0) --nesting;
        else if ((ch == ',' || ch == ')') && nesting == 0) {
          args.emplace_back(text.substr(start, p - start));
          start = p + 1;
          if (ch == ')') break;
        }
      }
      *after = p + 1;
      if (m.params.empty() && args.size() == 1 && args[0].find_first_not_of(" \t") == std::string::npos) args.clear();
      if (args.size() != m.params.size())
        fail(loc, "macro '" + name + "' takes " + std::to_string(m.params.size()) + " arguments, got " +
                      std::to_string(args.size()));
      for (std::string& a : args) a = expand_text(a, hidden, loc, depth + 1);
      // Parameters are replaced by their (expanded) arguments.
      std::string substituted;
      for (size_t k = 0; k < body.size();) {
        if (is_ident_start(body[k]) && (k == 0 || !is_ident_char(body[k - 1]))) {
          size_t e = k;
          while (e < body.size() && is_ident_char(body[e])) ++e;
          const std::string_view word(body.data() + k, e - k);
          auto param = std::find(m.params.begin(), m.params.end(), word);
          if (param != m.params.end()) substituted += args[static_cast<size_t>(param - m.params.begin())];
          else substituted.append(word);
          k = e;
        } else {
          substituted += body[k++];
        }
        if (substituted.size() > kMaxExpansionBytes) fail(loc, "macro expansion too large (more than 1 MiB)");
      }
      body = std::move(substituted);
    }
    hidden.push_back(name);
    *replacement = expand_text(body, hidden, loc, depth + 1);
    hidden.pop_back();
    return true;
  }

  // Copies a line to `out`, macros expanded; an expansion takes the place of its name.
  void expand_line(const LogicalLine& in, LogicalLine& out) {
    const std::string& t = in.text;
    size_t copied = 0, i = 0;
    std::vector<std::string> hidden;
    bool in_string = false;
    while (i < t.size()) {
      const char c = t[i];
      if (in_string || c == '"') {
        in_string = c == '"' ? !in_string : in_string;
        if (c == '\\' && in_string) ++i;
        ++i;
        continue;
      }
      if (!is_ident_start(c) || (i > 0 && (is_ident_char(t[i - 1]) || t[i - 1] == '.'))) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < t.size() && is_ident_char(t[j])) ++j;
      size_t after = j;
      std::string replacement;
      const SourceLoc loc = in.loc(i);
      if (expand_name(t.substr(i, j - i), t, &after, hidden, loc, 0, &replacement)) {
        append_source(out, in, copied, i);
        out.pieces.push_back({out.text.size(), loc.line, loc.column, loc.file});
        out.text += replacement;
        if (out.text.size() > kMaxExpansionBytes) fail(loc, "macro expansion too large (more than 1 MiB)");
        copied = i = after;
      } else {
        i = j;
      }
    }
    append_source(out, in, copied, t.size());
    if (out.pieces.empty()) out.pieces.push_back(in.pieces.front());
  }

  // ---- #if ----
  double evaluate_condition(const LogicalLine& line, size_t p, size_t end, SourceLoc loc) {
    // `defined NAME` and `defined(NAME)` first, then macros, then the arithmetic.
    std::string text;
    const std::string& t = line.text;
    while (p < end) {
      if (is_ident_start(t[p]) && (p == 0 || !is_ident_char(t[p - 1]))) {
        size_t e = p;
        while (e < end && is_ident_char(t[e])) ++e;
        if (t.compare(p, e - p, "defined") == 0) {
          size_t q = e;
          while (q < end && is_space(t[q])) ++q;
          const bool paren = q < end && t[q] == '(';
          if (paren) ++q;
          while (q < end && is_space(t[q])) ++q;
          const size_t s = q;
          while (q < end && is_ident_char(t[q])) ++q;
          if (s == q) fail(line.loc(s), "'defined' needs a macro name");
          const bool yes = macros_.count(t.substr(s, q - s)) != 0;
          while (q < end && is_space(t[q])) ++q;
          if (paren) {
            if (q >= end || t[q] != ')') fail(line.loc(q), "expected ')' after 'defined(" + t.substr(s, q - s) + "'");
            ++q;
          }
          text += yes ? " 1 " : " 0 ";
          p = q;
          continue;
        }
        text.append(t, p, e - p);
        p = e;
        continue;
      }
      text += t[p++];
    }
    std::vector<std::string> hidden;
    const std::string expanded = expand_text(text, hidden, loc, 0);
    if (expanded.find_first_not_of(" \t") == std::string::npos) fail(loc, "#if needs a condition");
    ConditionParser parser{expanded, 0, loc, 0};
    const double v = parser.ternary();
    parser.spaces();
    if (parser.p < expanded.size()) fail(loc, "unexpected '" + std::string(1, expanded[parser.p]) + "' in the #if condition");
    return v;
  }

  // C's #if arithmetic over numbers; a name left after expansion is 0, as in C.
  struct ConditionParser {
    const std::string& s;
    size_t p;
    SourceLoc loc;
    int depth;
    void spaces() {
      while (p < s.size() && is_space(s[p])) ++p;
    }
    bool eat(std::string_view op) {
      spaces();
      if (s.compare(p, op.size(), op) != 0) return false;
      // "<" is not the start of "<=" or "<<", "&" not of "&&", "|" not of "||", "!" not of "!=".
      if (op.size() == 1 && p + 1 < s.size()) {
        const char next = s[p + 1];
        if ((op == "<" || op == ">") && (next == '=' || next == op[0])) return false;
        if ((op == "&" || op == "|") && next == op[0]) return false;
        if (op == "!" && next == '=') return false;
      }
      p += op.size();
      return true;
    }
    double ternary() {
      if (++depth > kMaxMacroDepth) fail(loc, "#if condition nested too deeply");
      const double c = logical_or();
      double v = c;
      if (eat("?")) {
        const double a = ternary();
        if (!eat(":")) fail(loc, "expected ':' in the #if condition's '?:'");
        const double b = ternary();
        v = c != 0 ? a : b;
      }
      --depth;
      return v;
    }
    double logical_or() {
      double v = logical_and();
      while (eat("||")) v = (logical_and() != 0) || v != 0;
      return v;
    }
    double logical_and() {
      double v = equality();
      while (eat("&&")) v = (equality() != 0) && v != 0;
      return v;
    }
    double equality() {
      double v = relational();
      for (;;) {
        if (eat("==")) v = v == relational();
        else if (eat("!=")) v = v != relational();
        else return v;
      }
    }
    double relational() {
      double v = additive();
      for (;;) {
        if (eat("<=")) v = v <= additive();
        else if (eat(">=")) v = v >= additive();
        else if (eat("<")) v = v < additive();
        else if (eat(">")) v = v > additive();
        else return v;
      }
    }
    double additive() {
      double v = multiplicative();
      for (;;) {
        if (eat("+")) v += multiplicative();
        else if (eat("-")) v -= multiplicative();
        else return v;
      }
    }
    double multiplicative() {
      double v = unary();
      for (;;) {
        if (eat("*")) {
          v *= unary();
        } else if (eat("/") || eat("%")) {
          const bool modulo = s[p - 1] == '%';
          const double d = unary();
          if (d == 0) fail(loc, "division by zero in the #if condition");
          v = modulo ? std::fmod(v, d) : v / d;
        } else {
          return v;
        }
      }
    }
    double unary() {
      if (++depth > kMaxMacroDepth) fail(loc, "#if condition nested too deeply");
      double v;
      if (eat("!")) v = unary() == 0;
      else if (eat("-")) v = -unary();
      else if (eat("+")) v = unary();
      else v = primary();
      --depth;
      return v;
    }
    double primary() {
      spaces();
      if (p >= s.size()) fail(loc, "the #if condition ends too early");
      if (s[p] == '(') {
        ++p;
        const double v = ternary();
        if (!eat(")")) fail(loc, "expected ')' in the #if condition");
        return v;
      }
      if (is_digit(s[p]) || s[p] == '.') {
        double v = 0;
        auto [ptr, ec] = std::from_chars(s.data() + p, s.data() + s.size(), v);
        if (ec != std::errc()) fail(loc, "malformed number in the #if condition");
        p = static_cast<size_t>(ptr - s.data());
        while (p < s.size() && (s[p] == 'u' || s[p] == 'U' || s[p] == 'l' || s[p] == 'L')) ++p;  // 1UL
        return v;
      }
      if (is_ident_start(s[p])) {
        while (p < s.size() && is_ident_char(s[p])) ++p;
        return 0;
      }
      fail(loc, "unexpected '" + std::string(1, s[p]) + "' in the #if condition");
    }
  };

  const ParseOptions& options_;
  std::string main_file_;
  std::vector<IncludedFile>& includes_;
  std::filesystem::path folder_;
  std::unordered_map<std::string, Macro> macros_;
  std::unordered_map<std::string, bool> overridable_;
  std::vector<Condition> conditions_;
  std::vector<std::filesystem::path> open_files_;
  detail::CpfgSource out_;
};

}  // namespace

bool is_cpfg_text(std::string_view text) {
  bool in_comment = false;
  bool in_directive = false;  // the lines a preprocessor line's trailing `\` joins to it
  size_t pos = 0;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") pos = 3;
  while (pos < text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view line = text.substr(pos, nl - pos);
    pos = nl + 1;
    std::string kept;  // the line without comments
    for (size_t i = 0; i < line.size(); ++i) {
      if (in_comment) {
        if (line.compare(i, 2, "*/") == 0) in_comment = false, ++i;
        continue;
      }
      if (line.compare(i, 2, "/*") == 0) {
        in_comment = true;
        ++i;
        continue;
      }
      if (line.compare(i, 2, "//") == 0) break;
      kept += line[i];
    }
    size_t i = 0;
    while (i < kept.size() && is_space(kept[i])) ++i;
    size_t last = kept.size();
    while (last > 0 && is_space(kept[last - 1])) --last;
    const bool joins_next = last > 0 && kept[last - 1] == '\\';
    if (in_directive || (i < kept.size() && kept[i] == '#')) {
      in_directive = joins_next;  // a preprocessor line, or one its `\` carried on
      continue;
    }
    if (i == kept.size()) continue;  // blank or comment
    std::string head = lower_ascii(std::string_view(kept).substr(i, 7));
    if (head != "lsystem") return false;
    i += 7;
    while (i < kept.size() && is_space(kept[i])) ++i;
    return i < kept.size() && kept[i] == ':';
  }
  return false;
}

namespace detail {

CpfgSource preprocess_cpfg(std::string_view text, const std::string& file, const ParseOptions& options,
                           std::vector<IncludedFile>& includes) {
  Preprocessor p(file, options, includes);
  return p.run(text);
}

}  // namespace detail

}  // namespace sylva::lsys
