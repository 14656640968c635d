// parser.cpp — reads .lsys text (docs/spec/grammar.md) into a compiled Grammar.
//
// Pipeline: validate UTF-8 → blank out /* */ comments (keeping line/column) → join
// continuation lines into logical lines that remember each byte's place → classify each
// line (comment, #define, directive, section, production) → module declarations and
// defines first, then directives, then productions, so declaration order is free except
// among defines. Expressions compile straight to bytecode (expr.h); an expression that
// reads no formal parameter and draws no random number is evaluated once and stored as a
// constant. Recursion is bounded (kMaxNesting) so hostile input cannot overflow the stack.
#include <algorithm>
#include <array>
#include <functional>
#include <numeric>
#include <optional>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unordered_map>

#include "core/util/file_io.h"
#include "lsystem/cpfg_preprocessor.h"
#include "lsystem/expr.h"
#include "lsystem/grammar.h"
#include "lsystem/source_text.h"
#include "lsystem/vlab_object.h"

namespace sylva::lsys {

namespace detail {

void validate_text(std::string_view text, uint32_t file) {
  uint32_t line = 1, col = 1;
  auto fail = [file](SourceLoc loc, std::string message) { detail::fail({loc.line, loc.column, file}, std::move(message)); };
  size_t i = 0;
  while (i < text.size()) {
    unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == 0) fail({line, col}, "binary file: NUL byte in grammar text");
    size_t len = 1;
    if (c >= 0x80) {
      uint32_t cp = 0;
      if ((c >> 5) == 0x6) len = 2, cp = c & 0x1f;
      else if ((c >> 4) == 0xE) len = 3, cp = c & 0x0f;
      else if ((c >> 3) == 0x1E) len = 4, cp = c & 0x07;
      else fail({line, col}, "invalid UTF-8 (is this a binary file?)");
      if (i + len > text.size()) fail({line, col}, "invalid UTF-8 (truncated sequence)");
      for (size_t k = 1; k < len; ++k) {
        unsigned char cc = static_cast<unsigned char>(text[i + k]);
        if ((cc >> 6) != 0x2) fail({line, col}, "invalid UTF-8 (is this a binary file?)");
        cp = (cp << 6) | (cc & 0x3f);
      }
      bool overlong = (len == 2 && cp < 0x80) || (len == 3 && cp < 0x800) ||
                      (len == 4 && cp < 0x10000);
      if (overlong || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
        fail({line, col}, "invalid UTF-8 (is this a binary file?)");
      // A BOM is read (and skipped) only as the text's first bytes; anywhere else it is
      // an invisible character that would become a module of its own.
      if (cp == 0xFEFF && i != 0)
        fail({line, col}, "a byte order mark (U+FEFF) inside the text: only a file's first bytes may hold one "
                          "(were two files joined?)");
    }
    // CR is read as part of CRLF only: in a file with CR-only (classic Mac) line endings
    // every line would run into the next, giving a misleading error far from the cause.
    if (c == '\r' && (i + 1 == text.size() || text[i + 1] != '\n'))
      fail({line, col}, "a carriage return without a line feed after it: CR-only (classic Mac) line endings "
                        "are not read; save the file with LF or CRLF line endings");
    if (c == '\n') {
      ++line;
      col = 1;
    } else {
      col += static_cast<uint32_t>(len);
    }
    i += len;
  }
}

}  // namespace detail

namespace {

using namespace detail;  // NOLINT: the parser is the detail's main user

constexpr int kMaxNesting = 128;     // parentheses / unary operators / calls
constexpr int64_t kMaxSteps = 1000000;
constexpr int kMaxDepthLimit = 100000;
constexpr size_t kMaxPasses = 255;  // derive.cpp keys a pass's random streams by its index below 256

std::string quote_char(char c) {
  if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02x", static_cast<unsigned char>(c));
    return buf;
  }
  return std::string("'") + c + "'";
}

// Replaces /* ... */ comments by spaces, keeping newlines (so places do not move).
std::string blank_comments(std::string_view text) {
  std::string out(text);
  uint32_t line = 1, col = 1;
  for (size_t i = 0; i < out.size(); ++i) {
    if (out[i] == '/' && i + 1 < out.size() && out[i + 1] == '*') {
      SourceLoc start{line, col};
      size_t j = i + 2;
      while (j + 1 < out.size() && !(out[j] == '*' && out[j + 1] == '/')) ++j;
      if (j + 1 >= out.size()) fail(start, "unterminated comment: '/*' has no '*/'");
      for (size_t k = i; k < j + 2; ++k) {
        if (out[k] == '\n') {
          ++line;
          col = 1;
        } else {
          out[k] = ' ';
          ++col;
        }
      }
      i = j + 1;
      continue;
    }
    if (out[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return out;
}

// True if `s` (after leading spaces) is a '#' line that is not #define / #ignore.
bool is_comment_line(std::string_view s) {
  size_t i = 0;
  while (i < s.size() && is_space(s[i])) ++i;
  if (i >= s.size() || s[i] != '#') return false;
  std::string_view rest = s.substr(i + 1);
  auto starts_word = [&](std::string_view w) {
    return rest.substr(0, w.size()) == w &&
           (rest.size() == w.size() || !is_ident_char(rest[w.size()]));
  };
  return !(starts_word("define") || starts_word("ignore"));
}

std::vector<LogicalLine> logical_lines(const std::string& text) {
  std::vector<LogicalLine> lines;
  LogicalLine current;
  bool continuing = false;
  for_each_physical_line(text, [&](uint32_t line_no, std::string_view phys, bool last) {
    if (!continuing && is_comment_line(phys)) return;
    size_t keep = phys.size();
    while (keep > 0 && is_space(phys[keep - 1])) --keep;
    if (!continuing && keep == 0) return;  // blank: no logical line (every pass skips them)
    bool continues = keep > 0 && phys[keep - 1] == '\\';
    size_t take = continues ? keep - 1 : phys.size();
    // Appended with the string's own geometric growth: reserving exactly what each
    // physical line adds made 200,000 continuations quadratic (issue 32, item 11).
    current.pieces.push_back({current.text.size(), line_no, 1});
    const size_t capacity = current.text.capacity();
    current.text.append(phys.substr(0, take));
    if (current.text.capacity() != capacity) parse_work().line_bytes_copied += current.text.size() - take;
    if (continues && !last) {
      continuing = true;
    } else {
      ++parse_work().logical_lines;
      lines.push_back(std::move(current));
      current = LogicalLine{};
      continuing = false;
    }
  });
  return lines;
}

// A view of part of a logical line: [pos, end).
struct Cursor {
  const LogicalLine* line;
  size_t pos;
  size_t end;

  SourceLoc loc() const { return line->loc(pos); }
  SourceLoc loc_at(size_t p) const { return line->loc(p); }
  bool at_end() const { return pos >= end; }
  char peek(size_t ahead = 0) const {
    return pos + ahead < end ? line->text[pos + ahead] : '\0';
  }
  void skip_spaces() {
    while (pos < end && is_space(line->text[pos])) ++pos;
  }
  std::string_view rest() const { return std::string_view(line->text).substr(pos, end - pos); }
  Cursor sub(size_t b, size_t e) const { return Cursor{line, b, e}; }
};

// Finds `token` in [c.pos, c.end) outside parentheses; returns npos if absent.
size_t find_top_level(const Cursor& c, std::string_view token) {
  int depth = 0;
  const std::string& t = c.line->text;
  for (size_t i = c.pos; i < c.end; ++i) {
    char ch = t[i];
    if (ch == '(') ++depth;
    else if (ch == ')') depth = std::max(0, depth - 1);
    else if (depth == 0 && i + token.size() <= c.end && t.compare(i, token.size(), token) == 0)
      return i;
  }
  return std::string::npos;
}

// Formal parameter names in scope for one production.
using Scope = std::unordered_map<std::string, uint32_t>;

class Parser {
 public:
  Parser(Grammar& g, const ParseOptions& options) : g_(g), options_(options) {
    g_.program.functions = options.functions;
    g_.program.curves = options.curves;
  }

  void parse(const std::string& text);
  Word parse_word_line(const LogicalLine& line);

 private:
  // ---- expressions ----
  struct ExprBuild {
    uint32_t begin;
    bool uses_slot = false;
    bool uses_random = false;
    int depth = 0;      // current simulated stack depth
    int max_depth = 0;
    int nesting = 0;
  };
  Expr compile_expression(Cursor& c, const Scope* scope, bool allow_random = true);
  void emit(ExprBuild& b, Op op, uint32_t arg, SourceLoc loc, int stack_change,
            Func fn = Func::kSin);
  void parse_logical(Cursor& c, ExprBuild& b, const Scope* scope, char symbol, Op jump_op,
                     void (Parser::*operand)(Cursor&, ExprBuild&, const Scope*));
  void parse_or(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_and(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_equality(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_relational(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_additive(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_multiplicative(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_unary(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_power(Cursor& c, ExprBuild& b, const Scope* scope);
  void parse_primary(Cursor& c, ExprBuild& b, const Scope* scope);
  double parse_number(Cursor& c);
  double constant_expression(Cursor c, const char* what);

  // ---- module strings ----
  struct ParsedModule {
    SymbolId symbol;
    SourceLoc loc;
    std::vector<Cursor> args;  // argument texts (split at top-level commas)
  };
  std::vector<ParsedModule> parse_modules(Cursor c, const char* what);
  std::string_view module_name_at(Cursor& c);
  void check_builtin_arity(const ParsedModule& m);
  void check_brackets(const std::vector<ParsedModule>& ms, const char* what);
  Successor compile_successor(Cursor c, const Scope& scope, const char* what);
  Word evaluate_constant_word(const Successor& s);
  std::vector<PatternModule> compile_pattern(Cursor c, Scope& scope, const char* what);

  // ---- lines ----
  void parse_define(const LogicalLine& line);
  bool try_directive(const LogicalLine& line);
  // The part of the grammar its productions go to (sections `productions:`,
  // `decomposition:`, `homomorphism:`).
  enum class Section { kProductions, kDecomposition, kHomomorphism };
  Section section_ = Section::kProductions;
  void parse_production(const LogicalLine& line);
  void declare_modules(Cursor c);
  void set_ignore(Cursor c);

  // ---- cpfg model files (docs/cpfg.md) ----
  bool cpfg_line(const LogicalLine& line, std::string_view rest);
  void set_consider(Cursor c);
  // Statements (CPFG manual 3.2, 4.1): `{ ... }` at c, compiled into one program that leaves
  // 0 on the stack. With `scope` (a production) a new name assigned is a local slot there;
  // without (a block) it must be a global (collect_globals registered every block's).
  Expr compile_statements(Cursor& c, Scope* scope);
  void parse_block(Cursor& c, ExprBuild& b, Scope* scope);
  void parse_statement(Cursor& c, ExprBuild& b, Scope* scope);
  void parse_condition_in_parens(Cursor& c, ExprBuild& b, Scope* scope, const char* what);
  bool word_at(Cursor& c, std::string_view word);
  void collect_globals(const std::vector<LogicalLine>& lines);
  std::vector<LogicalLine> join_statement_lines(std::vector<LogicalLine> lines);

  Grammar& g_;
  const ParseOptions& options_;
  std::unordered_map<std::string, double> define_values_;
  bool have_axiom_ = false;
  bool pass_has_productions_ = false;  // the current pass (Grammar::passes.back()) has a production
  bool explicit_pass_ = false;         // a 'pass:' line started the current pass
  bool pass_line(const Cursor& c, std::string_view rest);
  bool seen_lsystem_ = false;  // cpfg: the 'Lsystem:' line was read
  bool seen_end_ = false;      // cpfg: the 'endlsystem' line was read (of the L-system being read)
  uint32_t lsystem_ = 0;       // cpfg: the L-system being read (Grammar::lsystem_labels), 0 the main one
  std::vector<std::array<bool, 4>> sub_block_seen_;  // by L-system: which of its four blocks were read
  bool sub_axiom_ = false;     // cpfg: the sub-L-system being read has its axiom
  // cpfg, by L-system: the modules a 'consider:' list names (by symbol id), when it has one:
  // its context passes over every other.
  std::vector<std::optional<std::vector<uint8_t>>> considered_{1};
  // The modules the L-system being read passes over in context (Grammar::ignored_in).
  std::vector<uint8_t>& ignored_here() { return lsystem_ ? g_.sub_lsystems[lsystem_ - 1].ignored : g_.ignored; }
  std::unordered_map<std::string, uint32_t> global_index_;  // cpfg: global variables by name
  std::unordered_map<std::string, uint32_t> array_index_;   // cpfg: arrays by name (Program::arrays)
  void define_arrays(Cursor value);
  void parse_printf(Cursor& c, ExprBuild& b, const Scope* scope, SourceLoc loc, bool to_file = false);
  void parse_fopen(Cursor& c, ExprBuild& b, SourceLoc loc);
  void parse_fscan(Cursor& c, ExprBuild& b, const Scope* scope, SourceLoc loc);
  void parse_file_argument(Cursor& c, ExprBuild& b, const Scope* scope, SourceLoc loc, const char* what);
  std::string string_literal(Cursor& c, const std::string& missing);
  // An element of array `name` ("a[i][j]" or "a[i, j]" at c): its global index pushed.
  void parse_array_element(Cursor& c, ExprBuild& b, const Scope* scope, const std::string& name, SourceLoc loc);
  bool globals_visible_ = false;  // compiling a production or a block: globals may be read
};

// ---------------------------------------------------------------- expressions

void Parser::emit(ExprBuild& b, Op op, uint32_t arg, SourceLoc loc, int stack_change, Func fn) {
  g_.program.code.push_back(Instr{op, fn, 0, arg});
  g_.program.locs.push_back(loc);
  b.depth += stack_change;
  b.max_depth = std::max(b.max_depth, b.depth);
}

Expr Parser::compile_expression(Cursor& c, const Scope* scope, bool allow_random) {
  c.skip_spaces();
  SourceLoc start = c.loc();
  ExprBuild b;
  b.begin = static_cast<uint32_t>(g_.program.code.size());
  if (c.at_end() || c.peek() == ',' || c.peek() == ')')
    fail(start, "expected an expression");
  parse_or(c, b, scope);
  if (b.max_depth > kMaxEvalStack) fail(start, "expression nested too deeply");
  if (b.uses_random && !allow_random)
    fail(start, "random functions are not allowed here");
  Expr e;
  e.loc = start;
  e.uses_random = b.uses_random;
  const uint32_t end = static_cast<uint32_t>(g_.program.code.size());
  if (end - b.begin == 1 && g_.program.code[b.begin].op == Op::kSlot) {
    e.kind = Expr::Kind::kSlot;
    e.slot = g_.program.code[b.begin].arg;
  } else if (!b.uses_slot && !b.uses_random) {
    // Fold: evaluate once now; errors (1/0, sqrt(-1)) are reported at their operator.
    Expr run{Expr::Kind::kProgram, false, 0, b.begin, end, 0, start};
    try {
      e.value = g_.program.eval(run, nullptr, nullptr);
    } catch (const EvalError& err) {
      fail(err.loc, err.message);
    }
    e.kind = Expr::Kind::kConst;
  } else {
    e.kind = Expr::Kind::kProgram;
    e.begin = b.begin;
    e.end = end;
    return e;
  }
  g_.program.code.resize(b.begin);
  g_.program.locs.resize(b.begin);
  return e;
}

// `||` and `&&` share one shape: operands joined by a doubled character, compiled with a
// short-circuit jump so the right operand is not evaluated when the left decides.
void Parser::parse_logical(Cursor& c, ExprBuild& b, const Scope* scope, char symbol, Op jump_op,
                           void (Parser::*operand)(Cursor&, ExprBuild&, const Scope*)) {
  (this->*operand)(c, b, scope);
  for (;;) {
    c.skip_spaces();
    if (!(c.peek() == symbol && c.peek(1) == symbol)) {
      if (c.peek() == symbol)
        fail(c.loc(), std::string("expected '") + symbol + symbol + "' ('" + symbol + "' alone is not an operator)");
      return;
    }
    SourceLoc loc = c.loc();
    c.pos += 2;
    size_t jump = g_.program.code.size();
    emit(b, jump_op, 0, loc, -1);
    (this->*operand)(c, b, scope);
    emit(b, Op::kBool, 0, loc, 0);
    g_.program.code[jump].arg = static_cast<uint32_t>(g_.program.code.size());
  }
}

// cpfg's printf("format", values...) (CPFG manual 3.2: C's printf in statements): the format a
// string literal with C's escapes, its conversions those check_format takes, one value each.
// It writes when evaluated (never folded into a constant) and is 0 as a value.
// A string literal at `c` (C's escapes \n \t \" \\), for printf's and fprintf's formats and
// fopen's arguments; `missing` is the error when there is none.
std::string Parser::string_literal(Cursor& c, const std::string& missing) {
  c.skip_spaces();
  if (c.peek() != '"') fail(c.loc(), missing);
  const SourceLoc format_loc = c.loc();
  ++c.pos;
  std::string format;
  for (;;) {
    if (c.at_end()) fail(format_loc, "the format string is not closed ('\"')");
    const char ch = c.peek();
    ++c.pos;
    if (ch == '"') break;
    if (ch != '\\') {
      format += ch;
      continue;
    }
    if (c.at_end()) fail(format_loc, "the format string is not closed ('\"')");
    const char e = c.peek();
    ++c.pos;
    switch (e) {
      case 'n': format += '\n'; break;
      case 't': format += '\t'; break;
      case '"': format += '"'; break;
      case '\\': format += '\\'; break;
      default: format += '\\', format += e; break;
    }
    if (format.size() > 4096) fail(format_loc, "a format string of more than 4096 characters");
  }
  return format;
}

// cpfg's fopen("name", "w" or "r") (CPFG manual 5.4): the file's id, a file in the model's
// folder written when fflush, fclose or the derivation's end comes, or read whole as it opens
// (ModelFiles). It opens when evaluated, never folded.
void Parser::parse_fopen(Cursor& c, ExprBuild& b, SourceLoc loc) {
  ++c.pos;  // '('
  std::string name = string_literal(c, "fopen needs the file's name in quotes: fopen(\"out.txt\", \"w\")");
  c.skip_spaces();
  if (c.peek() != ',') fail(c.loc(), "expected ',' and the mode after fopen's file name");
  ++c.pos;
  c.skip_spaces();
  const SourceLoc mode_loc = c.loc();
  const std::string mode = string_literal(c, "fopen needs its mode in quotes: \"w\" or \"r\"");
  if (mode != "w" && mode != "r") fail(mode_loc, "fopen's mode is \"w\" (writing) or \"r\" (reading)");
  c.skip_spaces();
  if (c.peek() != ')') fail(c.loc(), "expected ')' after fopen's mode");
  ++c.pos;
  b.uses_slot = true;  // a side effect: evaluated every time, never folded
  g_.program.formats.push_back(std::move(name));
  g_.program.code.push_back(Instr{mode == "r" ? Op::kFileRead : Op::kFileOpen, Func{}, 0,
                                  static_cast<uint32_t>(g_.program.formats.size() - 1)});
  g_.program.locs.push_back(loc);
  b.depth += 1;
  b.max_depth = std::max(b.max_depth, b.depth);
}

// cpfg's fscanf(file, "format", &a, &b[i], ...) (CPFG manual 5.4, which calls it fscan): reads
// numbers from a file fopen opened with "r" into variables — a production's parameter or a
// local it assigned before, a global, an array's element. Its value is C's: how many were
// read, or -1 at the file's end.
void Parser::parse_fscan(Cursor& c, ExprBuild& b, const Scope* scope, SourceLoc loc) {
  ++c.pos;  // '('
  parse_file_argument(c, b, scope, loc, "fscanf");
  c.skip_spaces();
  const SourceLoc format_loc = c.loc();
  std::string format = string_literal(c, "fscanf needs a format string after its file: fscanf(f, \"%f\", &x)");
  const FormatCheck check = check_scan_format(format);
  if (!check.error.empty()) fail(format_loc, check.error);
  Program::Scan scan;
  for (;;) {
    c.skip_spaces();
    if (c.peek() == ')') {
      ++c.pos;
      break;
    }
    if (c.peek() != ',') fail(c.loc(), "expected ',' or ')' in fscanf's arguments");
    ++c.pos;
    c.skip_spaces();
    const SourceLoc target_loc = c.loc();
    if (c.peek() != '&') fail(target_loc, "fscanf reads into variables: write '&' and the variable (&x, &a[i])");
    ++c.pos;
    c.skip_spaces();
    const SourceLoc name_loc = c.loc();
    if (!is_ident_start(c.peek())) fail(name_loc, "expected a variable's name after '&'");
    const size_t start = c.pos;
    while (is_ident_char(c.peek())) ++c.pos;
    const std::string name = c.line->text.substr(start, c.pos - start);
    c.skip_spaces();
    if (c.peek() == '[') {
      if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
      parse_array_element(c, b, scope, name, name_loc);  // pushes the element's global index
      --b.nesting;
      scan.local.push_back(0);
      continue;
    }
    uint32_t index = 0;
    if (scope && scope->count(name)) {
      index = scope->at(name);
      scan.local.push_back(1);
    } else if (global_index_.count(name)) {
      index = global_index_.at(name);
      scan.local.push_back(0);
    } else {
      fail(name_loc, "fscanf reads into a variable: '" + name + "' is no parameter, local assigned before, or global" +
                         (scope ? " (assign it first: " + name + " = 0;)" : ""));
    }
    g_.program.consts.push_back(static_cast<double>(index));
    emit(b, Op::kConst, static_cast<uint32_t>(g_.program.consts.size() - 1), name_loc, +1);
  }
  const int values = static_cast<int>(scan.local.size());
  if (values != check.values)
    fail(loc, "fscanf's format reads " + std::to_string(check.values) + (check.values == 1 ? " value" : " values") +
                  ", it was given " + std::to_string(values) + (values == 1 ? " variable" : " variables"));
  b.uses_slot = true;  // a side effect: evaluated every time, never folded
  g_.program.formats.push_back(std::move(format));
  scan.format = static_cast<uint32_t>(g_.program.formats.size() - 1);
  g_.program.scans.push_back(std::move(scan));
  g_.program.code.push_back(Instr{Op::kFileScan, Func{}, static_cast<uint16_t>(values),
                                  static_cast<uint32_t>(g_.program.scans.size() - 1)});
  g_.program.locs.push_back(loc);
  g_.uses_files = true;
  b.depth += -values;
  b.max_depth = std::max(b.max_depth, b.depth);
}

// The file's id, fprintf's or fscanf's (`what`) first argument, and the ',' after it.
void Parser::parse_file_argument(Cursor& c, ExprBuild& b, const Scope* scope, SourceLoc loc, const char* what) {
  if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
  parse_or(c, b, scope);
  --b.nesting;
  c.skip_spaces();
  if (c.peek() != ',') fail(c.loc(), std::string("expected ',' and the format after ") + what + "'s file");
  ++c.pos;
}

void Parser::parse_printf(Cursor& c, ExprBuild& b, const Scope* scope, SourceLoc loc, bool to_file) {
  ++c.pos;  // '('
  const char* what = to_file ? "fprintf" : "printf";
  if (to_file) parse_file_argument(c, b, scope, loc, what);  // fprintf(file, "format", values...)
  c.skip_spaces();
  const SourceLoc format_loc = c.loc();
  std::string format = string_literal(c, to_file ? "fprintf needs a format string after its file: fprintf(f, \"x = %g\\n\", x)"
                                                 : "printf needs a format string first: printf(\"x = %g\\n\", x)");
  const FormatCheck check = check_format(format);
  if (!check.error.empty()) fail(format_loc, check.error);
  int values = 0;
  for (;;) {
    c.skip_spaces();
    if (c.peek() == ')') {
      ++c.pos;
      break;
    }
    if (c.peek() != ',') fail(c.loc(), std::string("expected ',' or ')' in ") + what + "'s arguments");
    ++c.pos;
    if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
    parse_or(c, b, scope);
    --b.nesting;
    ++values;
  }
  if (values != check.values)
    fail(loc, std::string(what) + "'s format takes " + std::to_string(check.values) +
                  (check.values == 1 ? " value" : " values") + ", it was given " + std::to_string(values));
  b.uses_slot = true;  // a side effect: evaluated every time, never folded
  g_.program.formats.push_back(std::move(format));
  g_.program.code.push_back(Instr{to_file ? Op::kFilePrint : Op::kPrint, Func{}, static_cast<uint16_t>(values),
                                  static_cast<uint32_t>(g_.program.formats.size() - 1)});
  g_.program.locs.push_back(loc);
  if (to_file) g_.uses_files = true;
  b.depth += 1 - values - (to_file ? 1 : 0);
  b.max_depth = std::max(b.max_depth, b.depth);
}

void Parser::parse_or(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_logical(c, b, scope, '|', Op::kOrJump, &Parser::parse_and);
  // cpfg's conditional `c ? a : b` (its reader has C's `?` and `:` in expressions), right
  // associative, only the chosen branch evaluated. Not in sylva's own format.
  if (!g_.cpfg) return;
  c.skip_spaces();
  if (c.peek() != '?') return;
  const SourceLoc loc = c.loc();
  ++c.pos;
  if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
  const size_t to_else = g_.program.code.size();
  emit(b, Op::kJumpIfZero, 0, loc, -1);
  parse_or(c, b, scope);
  c.skip_spaces();
  if (c.peek() != ':') fail(c.loc(), "expected ':' in the conditional 'c ? a : b'");
  ++c.pos;
  const size_t to_end = g_.program.code.size();
  emit(b, Op::kJump, 0, loc, -1);  // the else branch pushes its own value
  g_.program.code[to_else].arg = static_cast<uint32_t>(g_.program.code.size());
  parse_or(c, b, scope);
  g_.program.code[to_end].arg = static_cast<uint32_t>(g_.program.code.size());
  --b.nesting;
}

void Parser::parse_and(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_logical(c, b, scope, '&', Op::kAndJump, &Parser::parse_equality);
}

void Parser::parse_equality(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_relational(c, b, scope);
  for (;;) {
    c.skip_spaces();
    Op op;
    if (c.peek() == '=' && c.peek(1) == '=') op = Op::kEq;
    else if (c.peek() == '!' && c.peek(1) == '=') op = Op::kNe;
    else if (c.peek() == '=') fail(c.loc(), "expected '==' to compare ('=' alone is not an operator)");
    else return;
    SourceLoc loc = c.loc();
    c.pos += 2;
    parse_relational(c, b, scope);
    emit(b, op, 0, loc, -1);
  }
}

void Parser::parse_relational(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_additive(c, b, scope);
  for (;;) {
    c.skip_spaces();
    Op op;
    size_t len = 1;
    if (c.peek() == '<') op = c.peek(1) == '=' ? (len = 2, Op::kLe) : Op::kLt;
    else if (c.peek() == '>') op = c.peek(1) == '=' ? (len = 2, Op::kGe) : Op::kGt;
    else return;
    SourceLoc loc = c.loc();
    c.pos += len;
    parse_additive(c, b, scope);
    emit(b, op, 0, loc, -1);
  }
}

void Parser::parse_additive(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_multiplicative(c, b, scope);
  for (;;) {
    c.skip_spaces();
    char ch = c.peek();
    if (ch != '+' && ch != '-') return;
    SourceLoc loc = c.loc();
    ++c.pos;
    parse_multiplicative(c, b, scope);
    emit(b, ch == '+' ? Op::kAdd : Op::kSub, 0, loc, -1);
  }
}

void Parser::parse_multiplicative(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_unary(c, b, scope);
  for (;;) {
    c.skip_spaces();
    char ch = c.peek();
    // cpfg's `%`: C's remainder of the operands made integers (its Eval); not in sylva's format.
    if (ch != '*' && ch != '/' && !(ch == '%' && g_.cpfg)) return;
    SourceLoc loc = c.loc();
    ++c.pos;
    parse_unary(c, b, scope);
    emit(b, ch == '*' ? Op::kMul : ch == '/' ? Op::kDiv : Op::kRem, 0, loc, -1);
  }
}

void Parser::parse_unary(Cursor& c, ExprBuild& b, const Scope* scope) {
  c.skip_spaces();
  char ch = c.peek();
  if ((ch == '-' || ch == '+' || ch == '!') && !(ch == '!' && c.peek(1) == '=')) {
    SourceLoc loc = c.loc();
    if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
    ++c.pos;
    parse_unary(c, b, scope);
    --b.nesting;
    if (ch == '-') emit(b, Op::kNeg, 0, loc, 0);
    else if (ch == '!') emit(b, Op::kNot, 0, loc, 0);
    return;
  }
  parse_power(c, b, scope);
}

void Parser::parse_power(Cursor& c, ExprBuild& b, const Scope* scope) {
  parse_primary(c, b, scope);
  c.skip_spaces();
  if (c.peek() == '^') {
    SourceLoc loc = c.loc();
    if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
    ++c.pos;
    parse_unary(c, b, scope);  // right-associative; 2^-1 allowed
    --b.nesting;
    emit(b, Op::kPow, 0, loc, -1);
  }
}

double Parser::parse_number(Cursor& c) {
  SourceLoc loc = c.loc();
  size_t start = c.pos;
  while (is_digit(c.peek())) ++c.pos;
  if (c.peek() == '.') {
    ++c.pos;
    while (is_digit(c.peek())) ++c.pos;
  }
  if ((c.peek() == 'e' || c.peek() == 'E') &&
      (is_digit(c.peek(1)) || ((c.peek(1) == '-' || c.peek(1) == '+') && is_digit(c.peek(2))))) {
    c.pos += 2;
    while (is_digit(c.peek())) ++c.pos;
  }
  const char* first = c.line->text.data() + start;
  const char* last = c.line->text.data() + c.pos;
  if (first + 1 == last && *first == '.') fail(loc, "expected a number after '.'");
  double value = 0;
  auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::result_out_of_range)
    fail(loc, "number out of range: '" + std::string(first, last) + "'");
  if (ec != std::errc() || ptr != last) fail(loc, "malformed number '" + std::string(first, last) + "'");
  if (is_ident_start(c.peek()))
    fail(c.loc(), "unexpected " + quote_char(c.peek()) + " after a number");
  return value;
}

void Parser::parse_primary(Cursor& c, ExprBuild& b, const Scope* scope) {
  c.skip_spaces();
  SourceLoc loc = c.loc();
  char ch = c.peek();
  if (c.at_end()) fail(loc, "expected an expression");
  if (is_digit(ch) || (ch == '.' && is_digit(c.peek(1)))) {
    double v = parse_number(c);
    g_.program.consts.push_back(v);
    emit(b, Op::kConst, static_cast<uint32_t>(g_.program.consts.size() - 1), loc, +1);
    return;
  }
  if (ch == '(') {
    if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
    ++c.pos;
    parse_or(c, b, scope);
    c.skip_spaces();
    if (c.peek() != ')') fail(c.loc(), "expected ')' to close the '(' at column " +
                                           std::to_string(loc.column));
    ++c.pos;
    --b.nesting;
    return;
  }
  if (is_ident_start(ch)) {
    size_t start = c.pos;
    while (is_ident_char(c.peek())) ++c.pos;
    std::string name = c.line->text.substr(start, c.pos - start);
    size_t after = c.pos;
    c.skip_spaces();
    if (c.peek() == '(' && name == "printf" && g_.cpfg) return parse_printf(c, b, scope, loc);
    if (c.peek() == '(' && name == "fprintf" && g_.cpfg) return parse_printf(c, b, scope, loc, true);
    if (c.peek() == '(' && name == "fopen" && g_.cpfg) {
      g_.uses_files = true;
      return parse_fopen(c, b, loc);
    }
    if (c.peek() == '(' && (name == "fscan" || name == "fscanf") && g_.cpfg) return parse_fscan(c, b, scope, loc);
    if (c.peek() == '(') {
      Func fn;
      if (!find_func(name, &fn)) fail(loc, "unknown function '" + name + "'");
      if (++b.nesting > kMaxNesting) fail(loc, "expression nested too deeply");
      ++c.pos;
      int args = 0;
      c.skip_spaces();
      if (c.peek() == ')') {
        ++c.pos;
      } else {
        for (;;) {
          parse_or(c, b, scope);
          ++args;
          c.skip_spaces();
          if (c.peek() == ',') {
            ++c.pos;
            continue;
          }
          if (c.peek() == ')') {
            ++c.pos;
            break;
          }
          fail(c.loc(), "expected ',' or ')' in the arguments of '" + name + "'");
        }
      }
      --b.nesting;
      const FuncInfo& info = func_info(fn);
      if (args != info.arity)
        fail(loc, "function '" + name + "' expects " + std::to_string(info.arity) +
                      (info.arity == 1 ? " argument" : " arguments") + ", got " +
                      std::to_string(args));
      if (info.random) b.uses_random = true;
      if (fn == Func::kStop || fn == Func::kFflush || fn == Func::kFclose) b.uses_slot = true;  // its effect is the call: never folded
      emit(b, Op::kCall, 0, loc, 1 - args, fn);
      return;
    }
    if (c.peek() == '[' && globals_visible_) {
      parse_array_element(c, b, scope, name, loc);
      b.uses_slot = true;  // not a constant: read when evaluated
      emit(b, Op::kLoadAt, 0, loc, 0);
      return;
    }
    c.pos = after;
    if (scope) {
      auto it = scope->find(name);
      if (it != scope->end()) {
        b.uses_slot = true;
        emit(b, Op::kSlot, it->second, loc, +1);
        return;
      }
    }
    if (globals_visible_) {
      auto it = global_index_.find(name);
      if (it != global_index_.end()) {
        b.uses_slot = true;  // not a constant: read when evaluated
        emit(b, Op::kGlobal, it->second, loc, +1);
        return;
      }
    }
    double value;
    auto it = define_values_.find(name);
    if (it != define_values_.end()) {
      value = it->second;
    } else if (name == "pi") {
      value = 3.14159265358979323846;
    } else {
      Func fn;
      if (find_func(name, &fn)) fail(loc, "function '" + name + "' needs arguments: " + name + "(...)");
      fail(loc, "unknown name '" + name + "'");
    }
    g_.program.consts.push_back(value);
    emit(b, Op::kConst, static_cast<uint32_t>(g_.program.consts.size() - 1), loc, +1);
    return;
  }
  if (ch == ')') fail(loc, "unexpected ')'");
  fail(loc, "expected an expression, found " + quote_char(ch));
}

// Compiles an expression that must use no formal parameters and no random numbers, and
// returns its value. Header values are evaluated once, before any seed is known, so a
// random draw there could not follow the seed: it is an error (draw in the axiom or a
// production instead).
double Parser::constant_expression(Cursor c, const char* what) {
  c.skip_spaces();
  if (c.at_end()) fail(c.loc(), std::string("expected a value for ") + what);
  Expr e = compile_expression(c, nullptr);
  c.skip_spaces();
  if (!c.at_end()) fail(c.loc(), "unexpected " + quote_char(c.peek()) + " after the value of " + what);
  if (e.kind != Expr::Kind::kConst)
    fail(e.loc, std::string("random functions are not allowed in ") + what +
                    " (it is evaluated before the seed is known); draw them in the axiom or a production");
  return e.value;
}

// ---------------------------------------------------------------- module strings

std::string_view Parser::module_name_at(Cursor& c) {
  size_t n = g_.symbols.module_name_length(c.rest());
  std::string_view name = std::string_view(c.line->text).substr(c.pos, n);
  c.pos += n;
  return name;
}

std::vector<Parser::ParsedModule> Parser::parse_modules(Cursor c, const char* what) {
  std::vector<ParsedModule> out;
  for (;;) {
    c.skip_spaces();
    if (c.at_end()) break;
    char ch = c.peek();
    SourceLoc loc = c.loc();
    if (ch == '(') {
      if (!out.empty() && c.pos > 0 && is_space(c.line->text[c.pos - 1]))
        fail(loc, "unexpected '(' (no space is allowed between a module name and its arguments)");
      fail(loc, std::string("unexpected '(' in ") + what);
    }
    if (ch == ')' || (ch == ',' && !g_.cpfg) || ch == ':')  // ',' is a module in cpfg (colour)
      fail(loc, "unexpected " + quote_char(ch) + " in " + what);
    std::string_view name = module_name_at(c);
    bool ok = true;
    SymbolId id = g_.symbols.intern(name, &ok);
    if (!ok) fail(loc, "too many different module names (more than 65535)");
    ParsedModule m{id, loc, {}};
    if (g_.cpfg) {
      // cpfg's reader skips blanks between tokens: `\ (90)` is `\(90)` (cpfg/lsys_input.l).
      const size_t before = c.pos;
      c.skip_spaces();
      if (c.peek() != '(') c.pos = before;
    }
    if (c.peek() == '(') {
      SourceLoc open = c.loc();
      ++c.pos;
      // Split the argument list at top-level commas.
      size_t arg_start = c.pos;
      int depth = 0;
      bool closed = false;
      while (!c.at_end()) {
        char a = c.peek();
        if (a == '"' && g_.cpfg) {  // @L's text: commas and parentheses inside do not count
          const size_t close = c.line->text.find('"', c.pos + 1);
          if (close == std::string::npos || close >= c.end) fail(c.loc(), "the string is not closed ('\"')");
          c.pos = close + 1;
          continue;
        }
        if (a == '(' || (a == '[' && g_.cpfg)) {  // an array's `G[i, j]` keeps its comma
          ++depth;
        } else if (a == ']' && g_.cpfg && depth > 0) {
          --depth;
        } else if (a == ')') {
          if (depth == 0) {
            m.args.push_back(c.sub(arg_start, c.pos));
            ++c.pos;
            closed = true;
            break;
          }
          --depth;
        } else if (a == ',' && depth == 0) {
          m.args.push_back(c.sub(arg_start, c.pos));
          arg_start = c.pos + 1;
        }
        ++c.pos;
      }
      if (!closed) fail(open, "'(' is never closed: expected ')'");
      if (m.args.size() > 65535) fail(open, "too many arguments (more than 65535)");
      // cpfg's label @L("format", values) (manual 6.10) is text in cpfg's window: sylva keeps
      // the values and drops the text, and draws nothing for it (docs/cpfg.md).
      if (g_.cpfg && name == "@L" && !m.args.empty()) {
        Cursor first = m.args.front();
        first.skip_spaces();
        if (first.peek() == '"') m.args.erase(m.args.begin());
      }
    }
    out.push_back(std::move(m));
  }
  return out;
}

void Parser::check_brackets(const std::vector<ParsedModule>& ms, const char* what) {
  std::vector<SourceLoc> open;
  for (const ParsedModule& m : ms) {
    if (m.symbol == kSymPush) {
      open.push_back(m.loc);
    } else if (m.symbol == kSymPop) {
      if (open.empty()) fail(m.loc, std::string("unbalanced brackets in ") + what + ": ']' without matching '['");
      open.pop_back();
    }
  }
  if (!open.empty())
    fail(open.back(), std::string("unbalanced brackets in ") + what + ": '[' is never closed");
}

// The modules whose parameter count is part of their meaning (light.md): a light query
// has 1 or 4 parameters, a turtle query 2 or 3, a tropism vector 3.
void Parser::check_builtin_arity(const ParsedModule& m) {
  // A cpfg file's ?E carries what its environmental program reads (honda81: vigor and
  // index): at least one parameter, the answer in the first (docs/cpfg.md).
  if (m.symbol == kSymLightQuery && g_.cpfg && m.args.empty())
    fail(m.loc, "?E needs a parameter for its answer: ?E(q)");
  if (m.symbol == kSymLightQuery && !g_.cpfg && m.args.size() != 1 && m.args.size() != 4)
    fail(m.loc, "?E takes 1 parameter, ?E(q), or 4, ?E(q, x, y, z), not " + std::to_string(m.args.size()) +
                    " (light.md)");
  if (is_turtle_query(m.symbol) && m.args.size() != 2 && m.args.size() != 3)
    fail(m.loc, std::string(m.symbol == kSymQueryPosition ? "?P" : m.symbol == kSymQueryHeading ? "?H"
                            : m.symbol == kSymQueryLeft   ? "?L"
                                                          : "?U") +
                    " takes 2 parameters, (x, y), or 3, (x, y, z), not " + std::to_string(m.args.size()) +
                    " (CPFG manual 6.9)");
  // In a cpfg file a bare @Tp is cpfg's (manual 6.8: undo the twist since the last segment).
  if (m.symbol == kSymTropismVector && m.args.size() != 3 && !(g_.cpfg && m.args.empty()))
    fail(m.loc, "@Tp takes 3 parameters, @Tp(x, y, z)" + std::string(g_.cpfg ? ", or none (CPFG manual 6.8)" : "") +
                    ", not " + std::to_string(m.args.size()));
}

Successor Parser::compile_successor(Cursor c, const Scope& scope, const char* what) {
  std::vector<ParsedModule> ms = parse_modules(c, what);
  check_brackets(ms, what);
  Successor s;
  for (ParsedModule& m : ms) {
    if ((m.symbol == kSymPush || m.symbol == kSymPop) && !m.args.empty())
      fail(m.loc, "brackets take no arguments");
    check_builtin_arity(m);
    SuccessorModule sm{m.symbol, static_cast<uint16_t>(m.args.size()),
                       static_cast<uint32_t>(s.args.size())};
    for (Cursor& a : m.args) {
      Expr e = compile_expression(a, &scope);
      a.skip_spaces();
      if (!a.at_end()) fail(a.loc(), "unexpected " + quote_char(a.peek()) + " in an argument");
      if (e.kind != Expr::Kind::kConst) s.all_constant = false;
      s.args.push_back(e);
    }
    if (m.symbol == kSymCut) g_.uses_cut = true;
    s.modules.push_back(sm);
  }
  if (s.all_constant) s.prebuilt = evaluate_constant_word(s);
  return s;
}

Word Parser::evaluate_constant_word(const Successor& s) {
  Word w;
  Rng rng = axiom_rng(g_.seed);
  std::vector<double> globals = g_.global_initial;  // a cpfg axiom's globals, before Start runs
  globals.push_back(0.0);
  EvalContext context{globals.data()};
  for (const SuccessorModule& sm : s.modules) {
    w.modules.push_back(Module{sm.symbol, sm.arg_count, static_cast<uint32_t>(w.params.size())});
    for (uint32_t k = 0; k < sm.arg_count; ++k) {
      const Expr& e = s.args[sm.first_arg + k];
      // Random arguments (only the axiom has them) are drawn by derive() from the seed's
      // stream; here they hold the value of the grammar's default seed.
      double v = e.kind == Expr::Kind::kConst ? e.value : 0.0;
      if (e.kind != Expr::Kind::kConst) {
        try {
          v = g_.program.eval(e, nullptr, &rng, &context);
        } catch (const EvalError& err) {
          fail(err.loc, err.message);
        }
      }
      w.params.push_back(v);
    }
  }
  return w;
}

std::vector<PatternModule> Parser::compile_pattern(Cursor c, Scope& scope, const char* what) {
  std::vector<ParsedModule> ms = parse_modules(c, what);
  std::vector<PatternModule> out;
  for (ParsedModule& m : ms) {
    if ((m.symbol == kSymPush || m.symbol == kSymPop) && !m.args.empty())
      fail(m.loc, "brackets take no arguments");
    check_builtin_arity(m);
    PatternModule pm{m.symbol, static_cast<uint16_t>(m.args.size()), 0};
    pm.first_slot = static_cast<uint32_t>(scope.size());
    for (Cursor& a : m.args) {
      a.skip_spaces();
      SourceLoc loc = a.loc();
      if (a.at_end()) fail(loc, "expected a parameter name");
      size_t start = a.pos;
      if (!is_ident_start(a.peek())) fail(loc, std::string("expected a parameter name in ") + what + ", found " + quote_char(a.peek()));
      while (is_ident_char(a.peek())) ++a.pos;
      std::string name = a.line->text.substr(start, a.pos - start);
      a.skip_spaces();
      if (!a.at_end()) fail(a.loc(), "expected ',' or ')' after parameter '" + name + "'");
      if (scope.count(name)) fail(loc, "formal parameter '" + name + "' is declared twice");
      if (define_values_.count(name))
        fail(loc, "formal parameter '" + name + "' hides the #define of the same name");
      uint32_t slot = static_cast<uint32_t>(scope.size());
      scope.emplace(name, slot);
    }
    out.push_back(pm);
  }
  return out;
}

// ---------------------------------------------------------------- lines

void Parser::parse_define(const LogicalLine& line) {
  Cursor c{&line, 0, line.text.size()};
  c.skip_spaces();
  c.pos += 7;  // "#define"
  c.skip_spaces();
  SourceLoc loc = c.loc();
  if (!is_ident_start(c.peek())) fail(loc, "#define needs a name: '#define NAME value'");
  size_t start = c.pos;
  while (is_ident_char(c.peek())) ++c.pos;
  std::string name = line.text.substr(start, c.pos - start);
  Func fn;
  if (name == "pi" || find_func(name, &fn))
    fail(loc, "#define cannot redefine the built-in '" + name + "'");
  if (define_values_.count(name))  // a hash look-up: 400,000 defines were quadratic (issue 32)
    for (const Define& d : g_.defines)
      if (++parse_work().define_compares, d.name == name) fail(loc, "'" + name + "' is defined twice (first at line " + std::to_string(d.loc.line) + ")");
  Define d{name, 0, loc, false};
  auto ov = options_.define_overrides.find(name);
  c.skip_spaces();
  if (c.at_end()) fail(c.loc(), "#define " + name + " needs a value");
  if (ov != options_.define_overrides.end()) {
    d.value = ov->second;
    d.overridden = true;
  } else {
    d.value = constant_expression(c, ("#define " + name).c_str());
  }
  define_values_[name] = d.value;
  g_.defines.push_back(d);
}

void Parser::declare_modules(Cursor c) {
  for (;;) {
    c.skip_spaces();
    if (c.at_end()) break;
    SourceLoc loc = c.loc();
    size_t start = c.pos;
    while (!c.at_end() && !is_space(c.peek())) ++c.pos;
    std::string name = c.line->text.substr(start, c.pos - start);
    if (is_digit(name[0]))
      fail(loc, "invalid module name '" + name + "': it must not start with a digit");
    for (char ch : name)
      if (ch == '(' || ch == ')' || ch == ',' || ch == ':' || ch == '[' || ch == ']' || ch == '<' || ch == '>')
        fail(loc, "invalid module name '" + name + "': it must not contain " + quote_char(ch));
    g_.symbols.declare_multichar(name);
    bool ok = true;
    g_.symbols.intern(name, &ok);
    if (!ok) fail(loc, "too many different module names (more than 65535)");
  }
}

void Parser::set_ignore(Cursor c) {
  std::vector<ParsedModule> ms = parse_modules(c, "the ignore list");
  if (considered_[lsystem_]) fail(c.loc(), "'consider:' and 'ignore:' cannot both be given");
  std::vector<uint8_t>& ignored = ignored_here();
  for (const ParsedModule& m : ms) {
    if (!m.args.empty()) fail(m.loc, "the ignore list takes module names without parameters");
    // cpfg's reader takes them and its context matching walks branches all the same: a
    // cpfg file's ignored brackets change nothing (docs/cpfg.md).
    if ((m.symbol == kSymPush || m.symbol == kSymPop) && g_.cpfg) continue;
    if (m.symbol == kSymPush || m.symbol == kSymPop)
      fail(m.loc, "brackets cannot be ignored: they delimit branches");
    if (ignored.size() <= m.symbol) ignored.resize(m.symbol + 1u, 0);
    ignored[m.symbol] = 1;
  }
}

// Directives: name -> kind. Returns false if the line is not a directive.
bool Parser::try_directive(const LogicalLine& line) {
  static const char* const kNames[] = {
      "module", "ignore", "angle", "width decrement", "width", "step", "tropism", "seed",
      "derivation length", "steps", "axiom", "\xCF\x89" /* ω */, "maximum depth"};
  Cursor c{&line, 0, line.text.size()};
  c.skip_spaces();
  std::string_view rest = c.rest();
  const std::string folded = g_.cpfg ? lower_ascii(rest.substr(0, 24)) : std::string();
  for (const char* name : kNames) {
    size_t n = std::strlen(name);
    if ((g_.cpfg ? std::string_view(folded).substr(0, n) : rest.substr(0, n)) != name) continue;
    size_t p = n;
    while (p < rest.size() && is_space(rest[p])) ++p;
    if (p >= rest.size() || rest[p] != ':') continue;
    Cursor value = c.sub(c.pos + p + 1, line.text.size());
    value.skip_spaces();
    std::string d = name;
    SourceLoc loc = c.loc();
    if (d == "module") {
      // handled in the first pass
    } else if (lsystem_ > 0 && (d == "derivation length" || d == "steps" || d == "seed")) {
      // A sub-L-system's own derivation length: the main L-system's counts (CPFG manual 7.2).
      constant_expression(value, d.c_str());
    } else if (d == "ignore") {
      set_ignore(value);
    } else if (d == "angle") {
      g_.turtle.angle_deg = constant_expression(value, "angle");
    } else if (d == "width decrement") {
      g_.turtle.width_decrement = constant_expression(value, "width decrement");
    } else if (d == "width") {
      double w = constant_expression(value, "width");
      if (w < 0) fail(loc, "width must not be negative");
      g_.turtle.width = w;
    } else if (d == "step") {
      g_.turtle.step = constant_expression(value, "step");
    } else if (d == "tropism") {
      // Four values separated by commas or spaces: T.x T.y T.z e.
      std::vector<Cursor> parts;
      if (find_top_level(value, ",") != std::string::npos) {
        size_t s = value.pos;
        for (;;) {
          Cursor rem = value.sub(s, value.end);
          size_t comma = find_top_level(rem, ",");
          if (comma == std::string::npos) {
            parts.push_back(rem);
            break;
          }
          parts.push_back(value.sub(s, comma));
          s = comma + 1;
        }
      } else {
        Cursor v = value;
        for (;;) {
          v.skip_spaces();
          if (v.at_end()) break;
          size_t s = v.pos;
          int depth = 0;
          while (!v.at_end() && (depth > 0 || !is_space(v.peek()))) {
            if (v.peek() == '(') ++depth;
            if (v.peek() == ')') --depth;
            ++v.pos;
          }
          parts.push_back(value.sub(s, v.pos));
        }
      }
      if (parts.size() != 4) fail(value.loc(), "tropism needs four values: x y z e");
      for (int k = 0; k < 3; ++k) g_.turtle.tropism[k] = constant_expression(parts[k], "tropism");
      g_.turtle.tropism_e = constant_expression(parts[3], "tropism");
      g_.turtle.has_tropism = true;
    } else if (d == "seed") {
      Cursor v = value;
      v.skip_spaces();
      std::string_view t = v.rest();
      while (!t.empty() && is_space(t.back())) t.remove_suffix(1);
      bool plain = !t.empty() && std::all_of(t.begin(), t.end(), is_digit);
      if (plain) {
        uint64_t s = 0;
        auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), s);
        if (ec != std::errc() || ptr != t.data() + t.size())
          fail(v.loc(), "seed out of range: it must be an integer from 0 to 18446744073709551615");
        g_.seed = s;
      } else {
        double s = constant_expression(value, "seed");
        if (s < 0 || s != std::floor(s) || s > 9007199254740992.0)
          fail(v.loc(), "seed must be a non-negative integer");
        g_.seed = static_cast<uint64_t>(s);
      }
    } else if (d == "derivation length" || d == "steps") {
      double n = constant_expression(value, "derivation length");
      if (n < 0 || n != std::floor(n)) fail(value.loc(), "derivation length must be a non-negative integer");
      if (n > kMaxSteps) fail(value.loc(), "derivation length is out of range (at most 1000000)");
      g_.steps = static_cast<int64_t>(n);
    } else if (d == "maximum depth") {
      double n = constant_expression(value, "maximum depth");
      if (n < 0 || n != std::floor(n) || n > kMaxDepthLimit)
        fail(value.loc(), "maximum depth must be an integer from 0 to 100000");
      // Each L-system has its own (CPFG manual 7.2; Grammar::SubLsystem).
      Grammar::SubLsystem* sub = lsystem_ ? &g_.sub_lsystems[lsystem_ - 1] : nullptr;
      int& depth = section_ == Section::kDecomposition ? (sub ? sub->decomposition_depth : g_.decomposition_depth)
                                                        : (sub ? sub->max_depth : g_.max_depth);
      depth = static_cast<int>(n);
    } else if (lsystem_ > 0) {
      // A sub-L-system's axiom is read and not used: it runs when ?(label, s) calls it
      // (CPFG manual 7.2: "the axiom is ignored when it is called as a sub-L-system").
      if (sub_axiom_) fail(loc, "the axiom is given twice");
      sub_axiom_ = true;
      const bool visible = globals_visible_;
      globals_visible_ = true;
      compile_successor(value, Scope{}, "the axiom");
      globals_visible_ = visible;
    } else {  // axiom / ω
      if (have_axiom_) fail(loc, "the axiom is given twice");
      have_axiom_ = true;
      // A cpfg axiom may read the globals its Start block set (cpfg evaluates it after Start).
      const bool visible = globals_visible_;
      globals_visible_ = g_.cpfg;
      Successor s = compile_successor(value, Scope{}, "the axiom");
      globals_visible_ = visible;
      if (!s.all_constant) {
        g_.axiom = evaluate_constant_word(s);
        g_.axiom_successor = std::move(s);
        g_.uses_random = true;
      } else {
        g_.axiom = std::move(s.prebuilt);
      }
      g_.axiom_loc = loc;
      if (g_.axiom.size() == 0) fail(value.loc(), "the axiom is empty");
    }
    return true;
  }
  return false;
}

void Parser::parse_production(const LogicalLine& line) {
  Cursor all{&line, 0, line.text.size()};
  all.skip_spaces();
  Production p;
  p.loc = all.loc();
  {
    std::string_view t = all.rest();
    while (!t.empty() && is_space(t.back())) t.remove_suffix(1);
    p.text = std::string(t);
  }
  size_t arrow = find_top_level(all, "->");
  if (arrow == std::string::npos) fail(all.loc(), "expected '->'");
  size_t arrow_len = 2;
  // "-->" is the arrow too, unless the '-' is the whole predecessor ("- -> +", "--> +").
  if (arrow > all.pos && line.text[arrow - 1] == '-') {
    Cursor before = all.sub(all.pos, arrow - 1);
    before.skip_spaces();
    if (!before.at_end()) {
      --arrow;
      arrow_len = 3;
    }
  }
  Cursor left = all.sub(all.pos, arrow);
  Cursor right = all.sub(arrow + arrow_len, line.text.size());

  // Label "p<digits>:" (sylva's format; cpfg has none: "AXIOM : c" is five modules and a condition).
  left.skip_spaces();
  if (!g_.cpfg) {
    size_t q = left.pos;
    while (q < left.end && is_ident_char(line.text[q])) ++q;
    size_t r = q;
    while (r < left.end && is_space(line.text[r])) ++r;
    if (q - left.pos >= 2 && r < left.end && line.text[r] == ':') {
      std::string word = line.text.substr(left.pos, q - left.pos);
      bool is_label = word[0] == 'p' && std::all_of(word.begin() + 1, word.end(), is_digit);
      SymbolId dummy;
      bool is_module = g_.symbols.find(word, &dummy) && g_.symbols.match_multichar(word) == word.size();
      if (is_label) {
        p.label = word;
        left.pos = r + 1;
      } else if (!is_module) {
        fail(left.loc(), "label '" + word + "' must be 'p' followed by digits, as in 'p1:'");
      }
    }
  }
  // Condition after the first top-level ':'.
  size_t colon = find_top_level(left, ":");
  Cursor context = left;
  Cursor cond_text = left;
  bool has_condition = false;
  if (colon != std::string::npos) {
    context.end = colon;
    cond_text = left.sub(colon + 1, left.end);
    cond_text.skip_spaces();
    if (cond_text.at_end()) fail(cond_text.loc(), "expected a condition after ':' (use '*' for always)");
    std::string_view ct = cond_text.rest();
    while (!ct.empty() && is_space(ct.back())) ct.remove_suffix(1);
    has_condition = ct != "*";
  }
  // Context split at top-level '<' and '>' (or lpfg's new context '<<' and '>>').
  size_t lt = find_top_level(context, "<");
  size_t gt = find_top_level(context, ">");
  if (lt != std::string::npos && gt != std::string::npos && gt < lt)
    fail(context.loc_at(gt), "the right context '>' must come after the left context '<'");
  const std::string& text = line.text;
  p.new_left = lt != std::string::npos && lt + 1 < context.end && text[lt + 1] == '<';
  p.new_right = gt != std::string::npos && gt + 1 < context.end && text[gt + 1] == '>';
  const size_t lt_len = p.new_left ? 2 : 1, gt_len = p.new_right ? 2 : 1;
  const char* lt_name = p.new_left ? "'<<'" : "'<'";
  const char* gt_name = p.new_right ? "'>>'" : "'>'";
  Cursor lctx = context.sub(context.pos, lt == std::string::npos ? context.pos : lt);
  Cursor pred = context.sub(lt == std::string::npos ? context.pos : lt + lt_len,
                            gt == std::string::npos ? context.end : gt);
  Cursor rctx = context.sub(gt == std::string::npos ? context.end : gt + gt_len, context.end);
  if (lt != std::string::npos) {
    Cursor t = lctx;
    t.skip_spaces();
    if (t.at_end()) fail(context.loc_at(lt), std::string("expected a left context before ") + lt_name);
    const size_t again = find_top_level(context.sub(lt + lt_len, context.end), "<");
    if (again != std::string::npos) fail(context.loc_at(again), "a production has at most one left context");
  }
  if (gt != std::string::npos) {
    Cursor t = rctx;
    t.skip_spaces();
    if (t.at_end()) fail(context.loc_at(gt), std::string("expected a right context after ") + gt_name);
    const size_t again = find_top_level(context.sub(gt + gt_len, context.end), ">");
    if (again != std::string::npos) fail(context.loc_at(again), "a production has at most one right context");
  }
  if (p.new_left || p.new_right) {
    const SourceLoc at = context.loc_at(p.new_left ? lt : gt);
    if (section_ != Section::kProductions)
      fail(at, std::string("new context (") + (p.new_left ? lt_name : gt_name) +
                   ") reads the word a derivation pass is writing: it belongs to the productions, not to the " +
                   (section_ == Section::kHomomorphism ? "homomorphism" : "decomposition"));
    const bool backward = g_.passes.back().backward;
    if (p.new_left && backward)
      fail(at, "'<<' reads the new word to the left, which a backward pass has not written yet: put this "
               "production under 'pass: forward' (docs/grammar-notes.md \"Passes\")");
    if (p.new_right && !backward)
      fail(at, "'>>' reads the new word to the right, which a forward pass has not written yet: put this "
               "production under 'pass: backward' (docs/grammar-notes.md \"Passes\")");
  }
  if (section_ == Section::kProductions) {
    p.pass = static_cast<uint32_t>(g_.passes.size() - 1);
    pass_has_productions_ = true;
  }
  Scope scope;
  {
    Cursor t = pred;
    t.skip_spaces();
    if (t.at_end()) fail(t.loc(), "expected a predecessor module before '->'");
    std::vector<PatternModule> pm = compile_pattern(pred, scope, "the predecessor");
    // cpfg's reader takes a strict predecessor of several modules (`f?E(x) --> ...`, its
    // PredDiff): they match consecutive modules of the word and are rewritten together.
    if (pm.size() != 1 && !(g_.cpfg && !pm.empty()))
      fail(t.loc(), "the predecessor must be one module (use '<' and '>' for context)");
    for (const PatternModule& m : pm)
      if (m.symbol == kSymPush || m.symbol == kSymPop) fail(t.loc(), "brackets cannot be rewritten");
    p.predecessor = pm[0];
    p.predecessor_tail.assign(pm.begin() + 1, pm.end());
  }
  p.left_context = compile_pattern(lctx, scope, "the left context");
  for (const PatternModule& m : p.left_context)
    if (m.symbol == kSymPush || m.symbol == kSymPop)
      fail(lctx.loc(), "brackets are not allowed in a left context");
  p.right_context = compile_pattern(rctx, scope, "the right context");
  p.slot_count = static_cast<uint32_t>(scope.size());
  if (p.has_context()) g_.uses_context = true;

  // Condition, and in a cpfg file the statements around it (CPFG manual 3.2):
  //   pred : {before} condition {after} --> successor
  globals_visible_ = g_.cpfg;
  Cursor cond = cond_text;
  if (g_.cpfg && has_condition) {
    cond.skip_spaces();
    if (cond.peek() == '{') p.before = compile_statements(cond, &scope);
    const size_t brace = find_top_level(cond, "{");
    if (brace != std::string::npos) {
      Cursor after = cond.sub(brace, cond.end);
      p.after = compile_statements(after, &scope);
      after.skip_spaces();
      if (!after.at_end()) fail(after.loc(), "unexpected " + quote_char(after.peek()) + " after the statements");
      cond.end = brace;
    }
    std::string_view ct = cond.rest();
    while (!ct.empty() && is_space(ct.back())) ct.remove_suffix(1);
    while (!ct.empty() && is_space(ct.front())) ct.remove_prefix(1);
    has_condition = !ct.empty() && ct != "*";
  }
  if (has_condition) {
    Cursor c = cond;
    p.condition = compile_expression(c, &scope);
    c.skip_spaces();
    if (!c.at_end()) fail(c.loc(), "unexpected " + quote_char(c.peek()) + " in the condition");
    if (p.condition.uses_random) g_.uses_random = true;
  }

  // Successor and probability.
  size_t pcolon = find_top_level(right, ":");
  Cursor succ = right;
  if (pcolon != std::string::npos) {
    succ.end = pcolon;
    Cursor prob = right.sub(pcolon + 1, right.end);
    prob.skip_spaces();
    if (prob.at_end()) fail(prob.loc(), "expected a probability after ':'");
    p.probability = compile_expression(prob, &scope);
    prob.skip_spaces();
    if (!prob.at_end()) fail(prob.loc(), "unexpected " + quote_char(prob.peek()) + " in the probability");
    if (p.probability.kind == Expr::Kind::kConst && p.probability.value < 0)
      fail(p.probability.loc, "a probability must not be negative");
    g_.uses_random = true;
  }
  {
    Cursor t = succ;
    t.skip_spaces();
    std::string_view st = t.rest();
    while (!st.empty() && is_space(st.back())) st.remove_suffix(1);
    if (g_.cpfg && st == "*") succ.end = succ.pos;  // cpfg's empty successor (manual 3)
    else if (g_.cpfg && t.at_end()) fail(t.loc(), "expected a successor after '-->' (cpfg writes '*' for none)");
  }
  p.successor = compile_successor(succ, scope, "the successor");
  globals_visible_ = false;
  p.slot_count = static_cast<uint32_t>(scope.size());  // the formal parameters, then the locals
  for (const Expr& e : p.successor.args)
    if (e.uses_random) g_.uses_random = true;
  p.lsystem = lsystem_;
  (section_ == Section::kHomomorphism    ? g_.homomorphism
   : section_ == Section::kDecomposition ? g_.decomposition
                                          : g_.productions)
      .push_back(std::move(p));
}

// A line of a cpfg file that only cpfg has; true when it was one. Productions and the
// directives both formats share go on to the common code.
bool Parser::cpfg_line(const LogicalLine& line, std::string_view rest) {
  Cursor c{&line, 0, line.text.size()};
  c.skip_spaces();
  const std::string folded = lower_ascii(rest);
  // `word` then spaces then ':' (or the end, where `colon_optional`); *value the rest.
  auto keyword = [&](std::string_view word, bool colon_optional, Cursor* value) {
    if (folded.compare(0, word.size(), word) != 0) return false;
    size_t k = word.size();
    if (k < folded.size() && is_ident_char(folded[k])) return false;
    while (k < folded.size() && is_space(folded[k])) ++k;
    if (k < folded.size() && folded[k] == ':') ++k;
    else if (!(colon_optional && k == folded.size())) return false;
    if (value) *value = c.sub(c.pos + k, line.text.size());
    return true;
  };
  Cursor value = c;
  if (keyword("lsystem", false, &value)) {
    // "Lsystem: label" (CPFG manual 2, 7.2): the label, a whole number (0 without one), names
    // the L-system for ?(label, s); each after the first is a sub-L-system.
    value.skip_spaces();
    std::string_view text = value.rest();
    while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
    int64_t label = 0;
    if (!text.empty()) {
      auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), label);
      if (ec != std::errc() || ptr != text.data() + text.size() || label < 0)
        label = -1;  // a name ("Lsystem: plant"): no ?(label, s) can call it
    }
    if (seen_lsystem_) {
      if (!seen_end_) fail(c.loc(), "an L-system starts before the one above ends: 'endlsystem' first");
      if (label >= 0 && std::find(g_.lsystem_labels.begin(), g_.lsystem_labels.end(), label) != g_.lsystem_labels.end())
        fail(value.loc(), "a second L-system with the label " + std::to_string(label));
      lsystem_ = static_cast<uint32_t>(g_.lsystem_labels.size());
      seen_end_ = false;
      sub_axiom_ = false;
      section_ = Section::kProductions;
      g_.sub_lsystems.emplace_back();
      considered_.emplace_back();
    }
    g_.lsystem_labels.push_back(label);
    seen_lsystem_ = true;
    return true;
  }
  if (seen_end_) fail(c.loc(), "expected a sub-L-system's 'Lsystem:' line or nothing after 'endlsystem'");
  if (folded == "endlsystem") {
    seen_end_ = true;
    return true;
  }
  for (const char* part : {"homomorphism", "decomposition"}) {
    if (!keyword(part, true, &value)) continue;
    const std::string option = lower_ascii(value.rest());
    std::string_view o = option;
    while (!o.empty() && is_space(o.front())) o.remove_prefix(1);
    if (!o.empty() && o != "warnings" && o != "no warnings") {
      value.skip_spaces();
      fail(value.loc(), std::string("expected 'warnings' or 'no warnings' after '") + part + ":'");
    }
    const bool homomorphism = part[0] == 'h';
    if (homomorphism) g_.depth_warnings = o == "warnings";
    // Decomposition comes after the productions and before the homomorphism (manual 4.4).
    if (!homomorphism && section_ == Section::kHomomorphism)
      fail(c.loc(), "'decomposition:' must come before 'homomorphism:' (CPFG manual 4.4)");
    section_ = homomorphism ? Section::kHomomorphism : Section::kDecomposition;
    return true;
  }
  // The homomorphism's own generator (manual 4.3.3): sylva's homomorphism draws from streams
  // keyed by module and depth already, so a redraw never changes it; the value is read only.
  // Decomposition draws from the L-system's generator: it has no seed of its own (4.4).
  if (section_ == Section::kHomomorphism && keyword("seed", false, &value)) {
    constant_expression(value, "the homomorphism's seed");
    return true;
  }
  if (section_ == Section::kDecomposition && keyword("seed", false, nullptr))
    fail(c.loc(), "decomposition draws from the L-system's generator: it takes no 'seed:' (CPFG manual 4.4)");
  if (folded.compare(0, 4, "ring") == 0 && folded.find("lsystem") != std::string::npos) {
    // "ring lsystem" (manual 3.1.1), with any spacing, before the axiom.
    std::string words;
    for (char ch : folded)
      if (!is_space(ch)) words += ch;
    if (words != "ringlsystem" && words != "ringlsystem:") fail(c.loc(), "expected 'ring lsystem' (CPFG manual 3.1.1)");
    if (lsystem_ ? sub_axiom_ : have_axiom_)
      fail(c.loc(), "'ring lsystem' must come before the axiom (CPFG manual 3.1.1)");
    (lsystem_ ? g_.sub_lsystems[lsystem_ - 1].ring : g_.ring) = true;
    return true;
  }
  if (keyword("consider", false, &value)) {
    set_consider(value);
    return true;
  }
  if (keyword("define", false, nullptr)) return true;  // its arrays: define_arrays, before the productions
  const std::pair<const char*, Expr*> blocks[] = {{"start", &g_.start_block}, {"starteach", &g_.start_each_block},
                                                  {"endeach", &g_.end_each_block}, {"end", &g_.end_block}};
  for (size_t kind = 0; kind < 4; ++kind) {
    const auto& [block, main_expr] = blocks[kind];
    if (!keyword(block, false, &value)) continue;
    const std::string name(rest.substr(0, std::strlen(block)));
    // A sub-L-system's block runs after the main one's (Grammar::sub_blocks).
    Expr sub;
    Expr* expr = main_expr;
    if (lsystem_ > 0) {
      if (sub_block_seen_.size() <= lsystem_) sub_block_seen_.resize(lsystem_ + 1);
      if (sub_block_seen_[lsystem_][kind]) fail(c.loc(), "the '" + name + ":' block is given twice");
      sub_block_seen_[lsystem_][kind] = true;
      expr = &sub;
    }
    if (expr->kind != Expr::Kind::kNone) fail(c.loc(), "the '" + name + ":' block is given twice");
    *expr = compile_statements(value, nullptr);
    if (lsystem_ > 0) g_.sub_blocks[kind].push_back(sub);
    value.skip_spaces();
    if (value.peek() == ';') ++value.pos;  // cpfg writes "Start: { ... };"
    value.skip_spaces();
    if (!value.at_end()) fail(value.loc(), "unexpected " + quote_char(value.peek()) + " after the '" + name + ":' block");
    return true;
  }
  return false;
}

// A `pass: forward` or `pass: backward` line (docs/grammar-notes.md "Passes"): the productions
// after it, up to the next, form one pass of every derivation step. The first such line
// before any production gives the implicit first pass its direction. True when it was one.
bool Parser::pass_line(const Cursor& c, std::string_view rest) {
  if (rest.substr(0, 4) != "pass") return false;
  size_t k = 4;
  while (k < rest.size() && is_space(rest[k])) ++k;
  if (k >= rest.size() || rest[k] != ':') return false;
  ++k;
  while (k < rest.size() && is_space(rest[k])) ++k;
  const SourceLoc at = c.loc_at(c.pos + k);
  const std::string_view dir = rest.substr(k);
  if (dir != "forward" && dir != "backward")
    fail(at, "expected 'forward' or 'backward' after 'pass:' (the direction the pass writes the new word in)");
  if (section_ != Section::kProductions)
    fail(c.loc(), "'pass:' splits the productions; it cannot stand in the homomorphism or decomposition");
  if (explicit_pass_ && !pass_has_productions_) fail(g_.passes.back().loc, "this pass has no productions");
  if (pass_has_productions_) {
    if (g_.passes.size() >= kMaxPasses) fail(c.loc(), "more than " + std::to_string(kMaxPasses) + " passes");
    g_.passes.emplace_back();
  }
  g_.passes.back().backward = dir == "backward";
  g_.passes.back().loc = c.loc();
  explicit_pass_ = true;
  pass_has_productions_ = false;
  return true;
}

void Parser::set_consider(Cursor c) {
  std::vector<ParsedModule> ms = parse_modules(c, "the consider list");
  std::optional<std::vector<uint8_t>>& considered = considered_[lsystem_];
  if (considered) fail(c.loc(), "'consider:' is given twice");
  for (uint8_t ignored : ignored_here())
    if (ignored) fail(c.loc(), "'consider:' and 'ignore:' cannot both be given");
  considered.emplace();
  for (const ParsedModule& m : ms) {
    if (!m.args.empty()) fail(m.loc, "the consider list takes module names without parameters");
    if (considered->size() <= m.symbol) considered->resize(m.symbol + 1u, 0);
    (*considered)[m.symbol] = 1;
  }
}

// ---------------------------------------------------------------- cpfg statements

bool Parser::word_at(Cursor& c, std::string_view word) {
  c.skip_spaces();
  if (c.rest().substr(0, word.size()) != word) return false;
  if (c.pos + word.size() < c.end && is_ident_char(c.line->text[c.pos + word.size()])) return false;
  c.pos += word.size();
  return true;
}

Expr Parser::compile_statements(Cursor& c, Scope* scope) {
  c.skip_spaces();
  const SourceLoc start = c.loc();
  ExprBuild b;
  b.begin = static_cast<uint32_t>(g_.program.code.size());
  const bool visible = globals_visible_;
  globals_visible_ = true;
  parse_block(c, b, scope);
  globals_visible_ = visible;
  g_.program.consts.push_back(0.0);  // what the program leaves: evaluation returns a value
  emit(b, Op::kConst, static_cast<uint32_t>(g_.program.consts.size() - 1), start, +1);
  if (b.max_depth > kMaxEvalStack) fail(start, "statements nested too deeply");
  Expr e;
  e.kind = Expr::Kind::kProgram;
  e.loc = start;
  e.uses_random = b.uses_random;
  e.begin = b.begin;
  e.end = static_cast<uint32_t>(g_.program.code.size());
  if (e.uses_random) g_.uses_random = true;
  return e;
}

void Parser::parse_block(Cursor& c, ExprBuild& b, Scope* scope) {
  c.skip_spaces();
  const SourceLoc open = c.loc();
  if (c.peek() != '{') fail(open, "expected '{' (cpfg statements are blocks in braces, CPFG manual 3.2)");
  if (++b.nesting > kMaxNesting) fail(open, "statements nested too deeply");
  ++c.pos;
  for (;;) {
    c.skip_spaces();
    if (c.at_end()) fail(open, "'{' is never closed: expected '}'");
    if (c.peek() == '}') break;
    parse_statement(c, b, scope);
  }
  ++c.pos;
  --b.nesting;
}

void Parser::parse_condition_in_parens(Cursor& c, ExprBuild& b, Scope* scope, const char* what) {
  c.skip_spaces();
  if (c.peek() != '(') fail(c.loc(), std::string("expected '(' after '") + what + "'");
  ++c.pos;
  parse_or(c, b, scope);
  c.skip_spaces();
  if (c.peek() != ')') fail(c.loc(), std::string("expected ')' to close the condition of '") + what + "'");
  ++c.pos;
}

// The operator of a compound assignment at `c` ('+' for "+=", and -, *, /), stepping
// over it to its '='; 0 (and `c` unmoved) for anything else.
char compound_assignment(Cursor& c) {
  const char op = c.peek();
  if ((op == '+' || op == '-' || op == '*' || op == '/') && c.peek(1) == '=') {
    ++c.pos;
    return op;
  }
  return 0;
}

Op compound_op(char op) { return op == '+' ? Op::kAdd : op == '-' ? Op::kSub : op == '*' ? Op::kMul : Op::kDiv; }

void Parser::parse_statement(Cursor& c, ExprBuild& b, Scope* scope) {
  c.skip_spaces();
  const SourceLoc loc = c.loc();
  auto here = [&] { return static_cast<uint32_t>(g_.program.code.size()); };
  auto patch = [&](uint32_t at, uint32_t target) { g_.program.code[at].arg = target; };
  if (word_at(c, "if")) {
    parse_condition_in_parens(c, b, scope, "if");
    const uint32_t skip = here();
    emit(b, Op::kJumpIfZero, 0, loc, -1);
    parse_block(c, b, scope);
    Cursor peek = c;
    if (word_at(peek, "else")) {
      c = peek;
      const uint32_t over = here();
      emit(b, Op::kJump, 0, loc, 0);
      patch(skip, here());
      Cursor next = c;
      if (word_at(next, "if")) parse_statement(c, b, scope);  // else if
      else parse_block(c, b, scope);
      patch(over, here());
    } else {
      patch(skip, here());
    }
    return;
  }
  if (word_at(c, "while")) {
    const uint32_t top = here();
    parse_condition_in_parens(c, b, scope, "while");
    const uint32_t exit = here();
    emit(b, Op::kJumpIfZero, 0, loc, -1);
    parse_block(c, b, scope);
    emit(b, Op::kLoop, top, loc, 0);
    patch(exit, here());
    return;
  }
  if (word_at(c, "do")) {
    const uint32_t top = here();
    parse_block(c, b, scope);
    if (!word_at(c, "while")) fail(c.loc(), "expected 'while (condition)' after the block of 'do'");
    parse_condition_in_parens(c, b, scope, "while");
    const uint32_t exit = here();
    emit(b, Op::kJumpIfZero, 0, loc, -1);
    emit(b, Op::kLoop, top, loc, 0);
    patch(exit, here());
    c.skip_spaces();
    if (c.peek() == ';') ++c.pos;
    return;
  }
  // An assignment "name = expr;" (or += -= *= /=), else an expression used as a statement.
  Cursor probe = c;
  if (is_ident_start(probe.peek())) {
    const size_t name_start = probe.pos;
    while (is_ident_char(probe.peek())) ++probe.pos;
    const std::string name = c.line->text.substr(name_start, probe.pos - name_start);
    probe.skip_spaces();
    if (probe.peek() == '[') {
      // "a[i] = expr;" (or += -= *= /=): the element's index, then the value, stored.
      parse_array_element(probe, b, scope, name, loc);
      probe.skip_spaces();
      const char op = compound_assignment(probe);
      if (probe.peek() != '=' || probe.peek(1) == '=')
        fail(probe.loc(), "expected '=' after the element of '" + name + "' (an element is assigned, not used, as a statement)");
      const SourceLoc op_loc = probe.loc();
      ++probe.pos;
      c = probe;
      if (op) {
        emit(b, Op::kDup, 0, loc, +1);
        emit(b, Op::kLoadAt, 0, loc, 0);
      }
      parse_or(c, b, scope);
      if (op) emit(b, compound_op(op), 0, op_loc, -1);
      emit(b, Op::kStoreAt, 0, loc, -2);
      c.skip_spaces();
      if (c.peek() != ';') fail(c.loc(), "expected ';' after the assignment to '" + name + "[...]' (cpfg ends every one with ';')");
      ++c.pos;
      return;
    }
    const char compound = compound_assignment(probe);
    if (probe.peek() == '=' && probe.peek(1) != '=') {
      const SourceLoc op_loc = probe.loc();
      ++probe.pos;
      c = probe;
      // Where the value goes: a local or formal parameter, else a global, else a new one.
      bool global = false;
      uint32_t index = 0;
      if (scope && scope->count(name)) {
        index = scope->at(name);
      } else if (global_index_.count(name)) {
        global = true;
        index = global_index_.at(name);
      } else if (scope) {
        if (define_values_.count(name) || name == "pi") fail(loc, "'" + name + "' is a constant: it cannot be assigned");
        index = static_cast<uint32_t>(scope->size());
        scope->emplace(name, index);
      } else {
        fail(loc, "'" + name + "' is not a global variable");  // collect_globals found every one
      }
      if (compound) emit(b, global ? Op::kGlobal : Op::kSlot, index, loc, +1);
      parse_or(c, b, scope);
      if (compound) emit(b, compound_op(compound), 0, op_loc, -1);
      emit(b, global ? Op::kStoreGlobal : Op::kStore, index, loc, -1);
      c.skip_spaces();
      if (c.peek() != ';') fail(c.loc(), "expected ';' after the assignment to '" + name + "' (cpfg ends every one with ';')");
      ++c.pos;
      return;
    }
  }
  if (c.peek() == ';') {  // an empty statement
    ++c.pos;
    return;
  }
  parse_or(c, b, scope);
  emit(b, Op::kPop, 0, loc, -1);
  c.skip_spaces();
  if (c.peek() != ';') fail(c.loc(), "expected ';' after the statement");
  ++c.pos;
}

// The most elements all of a grammar's arrays may hold (docs/limits.md).
constexpr uint64_t kMaxArrayElements = 1'000'000;

// `define: { array a[d1, d2, ...] = { v, ... }; array b[n]; ... }` (CPFG manual 2.2.2): each
// array's elements become globals (row-major, 0 unless initialised), visible to every block,
// production and successor. Dimensions are constant positive integers; an initialiser
// gives at most as many constant values as the array has elements (the rest stay 0).
void Parser::define_arrays(Cursor c) {
  c.skip_spaces();
  if (c.peek() != '{') fail(c.loc(), "expected '{' after 'define:' (CPFG manual 2.2.2: define: { array a[3]; })");
  ++c.pos;
  uint64_t total = 0;
  for (const ArrayInfo& a : g_.program.arrays)
    total += std::accumulate(a.dims.begin(), a.dims.end(), uint64_t{1}, std::multiplies<>());
  for (;;) {
    c.skip_spaces();
    if (c.peek() == '}') {
      ++c.pos;
      c.skip_spaces();
      if (c.peek() == ';') ++c.pos;
      c.skip_spaces();
      if (!c.at_end()) fail(c.loc(), "unexpected " + quote_char(c.peek()) + " after the 'define:' block");
      return;
    }
    if (c.at_end()) fail(c.loc(), "the 'define:' block is never closed with '}'");
    if (!word_at(c, "array")) fail(c.loc(), "expected 'array name[size];' in the 'define:' block");
    c.skip_spaces();
    const SourceLoc name_loc = c.loc();
    if (!is_ident_start(c.peek())) fail(c.loc(), "expected the array's name after 'array'");
    const size_t start = c.pos;
    while (is_ident_char(c.peek())) ++c.pos;
    const std::string name = c.line->text.substr(start, c.pos - start);
    if (array_index_.count(name) || global_index_.count(name) || define_values_.count(name))
      fail(name_loc, "'" + name + "' is already defined");
    c.skip_spaces();
    if (c.peek() != '[') fail(c.loc(), "expected '[' and the array's size after '" + name + "'");
    ++c.pos;
    ArrayInfo a;
    a.name = name;
    uint64_t size = 1;
    for (;;) {
      c.skip_spaces();
      const SourceLoc at = c.loc();
      size_t end = c.pos;
      while (end < c.end && c.line->text[end] != ',' && c.line->text[end] != ']') ++end;
      if (end >= c.end) fail(at, "the size of '" + name + "' is never closed with ']'");
      const double d = constant_expression(c.sub(c.pos, end), "an array's size");
      if (!(d >= 1) || d != std::floor(d) || d > static_cast<double>(kMaxArrayElements))
        fail(at, "an array's size must be an integer from 1 to " + std::to_string(kMaxArrayElements));
      a.dims.push_back(static_cast<uint32_t>(d));
      size *= static_cast<uint64_t>(d);
      if (total + size > kMaxArrayElements)
        fail(at, "the arrays hold more than " + std::to_string(kMaxArrayElements) + " elements (docs/limits.md)");
      c.pos = end + 1;
      if (c.line->text[end] == ']') {
        // C's form of a further dimension, `a[M][N]`, as cpfg's reader takes it.
        c.skip_spaces();
        if (c.peek() != '[') break;
        ++c.pos;
      }
    }
    total += size;
    a.base = static_cast<uint32_t>(g_.global_names.size());
    for (uint64_t k = 0; k < size; ++k) g_.global_names.push_back(name + "[" + std::to_string(k) + "]");
    g_.global_initial.resize(g_.global_names.size(), 0.0);
    c.skip_spaces();
    if (c.peek() == '=') {
      ++c.pos;
      c.skip_spaces();
      if (c.peek() != '{') fail(c.loc(), "expected '{' and the values of '" + name + "'");
      ++c.pos;
      uint64_t k = 0;
      for (;;) {
        c.skip_spaces();
        const SourceLoc at = c.loc();
        size_t end = c.pos;
        while (end < c.end && c.line->text[end] != ',' && c.line->text[end] != '}') ++end;
        if (end >= c.end) fail(at, "the values of '" + name + "' are never closed with '}'");
        if (k >= size) fail(at, "'" + name + "' has " + std::to_string(size) + " elements: too many values");
        g_.global_initial[a.base + k++] = constant_expression(c.sub(c.pos, end), "an array's value");
        c.pos = end + 1;
        if (c.line->text[end] == '}') break;
      }
      c.skip_spaces();
    }
    if (c.peek() != ';') fail(c.loc(), "expected ';' after the array '" + name + "'");
    ++c.pos;
    array_index_.emplace(name, static_cast<uint32_t>(g_.program.arrays.size()));
    g_.program.arrays.push_back(std::move(a));
  }
}

// `[i, j]` or `[i][j]` after array `array`'s name: its indices, one per dimension, then
// kArrayIndex (the element's global index on the stack).
void Parser::parse_array_element(Cursor& c, ExprBuild& b, const Scope* scope, const std::string& name, SourceLoc loc) {
  auto found = array_index_.find(name);
  if (found == array_index_.end())
    fail(loc, "'" + name + "' is not an array (CPFG manual 2.2.2: 'define: { array " + name + "[n]; }')");
  const uint32_t array = found->second;
  const ArrayInfo& a = g_.program.arrays[array];
  const size_t rank = a.dims.size();
  size_t given = 0;
  c.skip_spaces();
  while (c.peek() == '[') {
    ++c.pos;
    for (;;) {
      if (++given > rank)
        fail(c.loc(), "'" + a.name + "' has " + std::to_string(rank) + (rank == 1 ? " dimension" : " dimensions"));
      parse_or(c, b, scope);
      c.skip_spaces();
      if (c.peek() == ',') {
        ++c.pos;
        continue;
      }
      if (c.peek() == ']') {
        ++c.pos;
        break;
      }
      fail(c.loc(), "expected ',' or ']' in the index of '" + a.name + "'");
    }
    c.skip_spaces();
    if (given == rank) break;
  }
  if (given != rank)
    fail(loc, "'" + a.name + "' has " + std::to_string(rank) + (rank == 1 ? " dimension" : " dimensions") +
                  ": give an index for each");
  emit(b, Op::kArrayIndex, array, loc, 1 - static_cast<int>(rank));
}

// Registers every name a Start/StartEach/EndEach/End block assigns as a global variable
// (CPFG manual 4.1), before anything is compiled, so a block may read a global another block
// (or a later line) assigns.
void Parser::collect_globals(const std::vector<LogicalLine>& lines) {
  for (const LogicalLine& line : lines) {
    const std::string folded = lower_ascii(line.text.substr(0, 16));
    size_t k = 0;
    while (k < folded.size() && is_space(folded[k])) ++k;
    bool block = false;
    for (const char* name : {"starteach", "start", "endeach", "end"}) {
      const size_t n = std::strlen(name);
      if (folded.compare(k, n, name) != 0) continue;
      size_t p = k + n;
      while (p < folded.size() && is_space(folded[p])) ++p;
      if (p < folded.size() && folded[p] == ':') block = true;
      break;
    }
    if (!block) continue;
    const std::string& t = line.text;
    for (size_t i = 0; i < t.size(); ++i) {
      if (t[i] == '"') {  // a printf format: no assignments inside
        const size_t close = t.find('"', i + 1);
        if (close == std::string::npos) break;
        i = close;
        continue;
      }
      if (!is_ident_start(t[i]) || (i > 0 && (is_ident_char(t[i - 1]) || t[i - 1] == '.'))) continue;
      size_t e = i;
      while (e < t.size() && is_ident_char(t[e])) ++e;
      // fscanf's target "&name" assigns it too (not "a && b").
      size_t amp = i;
      while (amp > 0 && is_space(t[amp - 1])) --amp;
      const bool address = amp > 0 && t[amp - 1] == '&' && (amp < 2 || t[amp - 2] != '&');
      size_t p = e;
      while (p < t.size() && is_space(t[p])) ++p;
      if (p < t.size() && (t[p] == '+' || t[p] == '-' || t[p] == '*' || t[p] == '/') && p + 1 < t.size() && t[p + 1] == '=') ++p;
      const bool indexed = p < t.size() && t[p] == '[';  // &a[i]: an array's element, no new global
      if ((address && !indexed) || (p < t.size() && t[p] == '=' && (p + 1 >= t.size() || t[p + 1] != '='))) {
        const std::string name = t.substr(i, e - i);
        if (!define_values_.count(name) && !global_index_.count(name)) {
          global_index_.emplace(name, static_cast<uint32_t>(g_.global_names.size()));
          g_.global_names.push_back(name);
          g_.global_initial.push_back(0.0);
        }
      }
      i = e - 1;
    }
  }
}

// Joins a cpfg line whose statement braces are still open to the lines after it, as cpfg
// reads blocks and statements over several lines. Braces count before a production's
// arrow only (after it, `{` and `}` are polygons, which may open in one production and close
// in another).
std::vector<LogicalLine> Parser::join_statement_lines(std::vector<LogicalLine> lines) {
  std::vector<LogicalLine> out;
  int depth = 0;
  bool counts_braces = false;  // whether the logical line being built may open statement braces
  for (LogicalLine& line : lines) {
    // A line that begins with a tab goes on the line before it (cpfg/lsys_input.l reads a
    // newline and a tab as a space). Its braces are statements' while the production it
    // continues has not reached its arrow yet.
    const bool tab_joined = depth == 0 && line.continues_previous && !out.empty();
    if (tab_joined && out.back().text.find("->") != std::string::npos) counts_braces = false;
    const bool continuing = depth > 0 || tab_joined;
    size_t end = line.text.size();
    if (size_t arrow = line.text.find("->"); arrow != std::string::npos) end = arrow;
    // Where statement braces may stand: a block's, or a production's after its ':' (an
    // axiom's braces are polygons).
    size_t from = 0;
    if (!continuing) {
      const std::string folded = lower_ascii(line.text.substr(0, 24));
      size_t k = 0;
      while (k < folded.size() && is_space(folded[k])) ++k;
      const size_t colon = line.text.find(':');
      from = colon == std::string::npos || colon >= end ? end : colon + 1;
      for (const char* header : {"axiom", "seed", "derivation", "ignore", "consider", "maximum", "lsystem"})
        if (folded.compare(k, std::strlen(header), header) == 0) from = end;
      counts_braces = from < line.text.size() && end == line.text.size();
    } else if (depth == 0 && !counts_braces) {
      from = end;
    }
    for (size_t i = from; i < end; ++i) {
      if (line.text[i] == '{') ++depth;
      else if (line.text[i] == '}' && depth > 0) --depth;
    }
    if (!continuing) {
      // A line that opens no statement braces stays as it is.
      out.push_back(std::move(line));
      continue;
    }
    LogicalLine& into = out.back();
    into.text += ' ';
    for (LogicalLine::Piece piece : line.pieces) {
      piece.offset += into.text.size();
      into.pieces.push_back(piece);
    }
    into.text += line.text;
  }
  return out;
}

enum class LineKind { kBlank, kDefine, kModule, kSection, kOther };

LineKind classify(const LogicalLine& line) {
  size_t i = 0;
  const std::string& t = line.text;
  while (i < t.size() && is_space(t[i])) ++i;
  if (i == t.size()) return LineKind::kBlank;
  std::string_view rest(t.data() + i, t.size() - i);
  if (rest.substr(0, 7) == "#define" && (rest.size() == 7 || !is_ident_char(rest[7])))
    return LineKind::kDefine;
  auto keyword = [&](std::string_view w) {
    if (rest.substr(0, w.size()) != w) return false;
    size_t p = w.size();
    while (p < rest.size() && is_space(rest[p])) ++p;
    return p < rest.size() && rest[p] == ':';
  };
  if (keyword("module")) return LineKind::kModule;
  return LineKind::kOther;
}

// The module names of the CPFG manual's chapter 6 that are longer than one character: a
// cpfg file reads `@Gs` as one module, as cpfg does.
constexpr const char* kCpfgModuleNames[] = {
    "@Gc", "@Ge", "@Gr", "@Gs", "@Gt", "@L",  "@O",  "@PC", "@PD", "@PS", "@T",  "@Td", "@Tf", "@Tp", "@Ts",
    "@Tx", "@Ti", "@bc", "@bo", "@c",  "@o",  "@v",  "@M",  "@m",  "@R",  "@D",  "@Di", "@Dd", "@;",  "@,",  "?P",
    "?H",  "?L",  "?U",  "?E",  "@!",  "@#"};

void Parser::parse(const std::string& text) {
  validate_text(text);
  std::vector<LogicalLine> lines;
  if (is_cpfg_text(text)) {
    // A cpfg model file (docs/cpfg.md): the C preprocessor first, cpfg's defaults.
    g_.cpfg = true;
    g_.turtle.angle_deg = 45;  // the view file's default angle increment (CPFG manual 8.1.1)
    g_.max_depth = 1;          // a homomorphism is applied once unless 'maximum depth:' says more
    g_.decomposition_depth = 1;  // ... and so is a decomposition (manual 4.4)
    g_.depth_warnings = false; // ... and says nothing of what is left unless asked (manual 4.3.1)
    g_.turtle.width = 1 * g_.turtle.width_scale;  // the initial line width, 1 (manual 8.1.1)
    std::string body = text;
    if (body.compare(0, 3, "\xEF\xBB\xBF") == 0) body.replace(0, 3, "   ");
    detail::CpfgSource source = detail::preprocess_cpfg(body, g_.file, options_, g_.includes);
    lines = join_statement_lines(std::move(source.lines));
    collect_globals(lines);
    g_.defines = std::move(source.defines);
    for (const char* name : kCpfgModuleNames) {
      g_.symbols.declare_multichar(name);
      g_.symbols.intern(name);
    }
  } else {
    std::string clean = blank_comments(text);
    size_t bom = clean.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    if (bom) clean.replace(0, 3, "   ");
    lines = logical_lines(clean);
  }

  // Pass 1: module declarations (they change how every module string is tokenised).
  for (const LogicalLine& line : lines) {
    if (classify(line) != LineKind::kModule) continue;
    Cursor c{&line, 0, line.text.size()};
    size_t colon = line.text.find(':');
    declare_modules(c.sub(colon + 1, line.text.size()));
  }
  // Pass 2: defines, in file order.
  for (const LogicalLine& line : lines)
    if (classify(line) == LineKind::kDefine) parse_define(line);
  for (const auto& [name, value] : options_.define_overrides) {
    if (!g_.cpfg && !define_values_.count(name))
      fail({0, 0}, "-D " + name + ": the grammar has no '#define " + name + "'");
  }
  // Pass 2b (cpfg): the arrays of 'define:', before anything that may read them is compiled.
  if (g_.cpfg)
    for (const LogicalLine& line : lines) {
      Cursor c{&line, 0, line.text.size()};
      c.skip_spaces();
      const std::string folded = lower_ascii(std::string(c.rest().substr(0, 7)));
      if (folded.compare(0, 6, "define") != 0 || (folded.size() > 6 && is_ident_char(folded[6]))) continue;
      Cursor v = c.sub(c.pos + 6, line.text.size());
      v.skip_spaces();
      if (v.peek() != ':') continue;
      ++v.pos;
      define_arrays(v);
    }
  // Pass 3: directives, sections and productions.
  for (const LogicalLine& line : lines) {
    LineKind kind = classify(line);
    if (kind != LineKind::kOther) continue;
    Cursor c{&line, 0, line.text.size()};
    c.skip_spaces();
    std::string_view rest = c.rest();
    while (!rest.empty() && is_space(rest.back())) rest.remove_suffix(1);
    if (g_.cpfg && cpfg_line(line, rest)) continue;
    if (rest.substr(0, 7) == "#ignore") {
      Cursor v = c.sub(c.pos + 7, line.text.size());
      v.skip_spaces();
      if (v.peek() == ':') ++v.pos;
      set_ignore(v);
      continue;
    }
    auto section = [&](std::string_view name) {
      if (rest.substr(0, name.size()) != name) return false;
      std::string_view after = rest.substr(name.size());
      size_t k = 0;
      while (k < after.size() && is_space(after[k])) ++k;
      if (k >= after.size() || after[k] != ':') return false;
      ++k;
      while (k < after.size() && is_space(after[k])) ++k;
      if (k != after.size())
        fail(c.loc_at(c.pos + name.size() + k), "unexpected text after '" + std::string(name) + ":'");
      return true;
    };
    if (section("productions")) {
      section_ = Section::kProductions;
      continue;
    }
    if (pass_line(c, rest)) continue;
    if (section("decomposition")) {
      section_ = Section::kDecomposition;
      continue;
    }
    if (section("homomorphism") || section("interpretation")) {
      section_ = Section::kHomomorphism;
      continue;
    }
    if (find_top_level(c, "->") != std::string::npos) {
      parse_production(line);
      continue;
    }
    if (try_directive(line)) continue;
    // "name words:" that is no known directive.
    size_t k = 0;
    while (k < rest.size() && (is_ident_char(rest[k]) || rest[k] == ' ')) ++k;
    if (k > 0 && k < rest.size() && rest[k] == ':' && is_ident_start(rest[0])) {
      std::string name(rest.substr(0, k));
      while (!name.empty() && name.back() == ' ') name.pop_back();
      fail(c.loc(), "unknown directive '" + name + "'");
    }
    if (rest[0] == '#')
      fail(c.loc(), "unknown directive '" + std::string(rest.substr(0, rest.find_first_of(" \t:"))) + "'");
    fail(c.loc(), "expected a production 'predecessor -> successor' or a directive 'name: value'");
  }
  if (g_.cpfg && !seen_end_)
    fail(lines.empty() ? SourceLoc{1, 1} : lines.back().loc(lines.back().text.size()),
         "the L-system has no 'endlsystem' line (CPFG manual 2)");
  if (!have_axiom_) fail({1, 1}, g_.cpfg ? "no axiom: the L-system needs a line 'Axiom: <modules>'"
                                         : "no axiom: the grammar needs a line 'axiom: <modules>'");

  // Index productions by predecessor symbol; size per-symbol tables.
  const size_t nsym = g_.symbols.size();
  g_.resize_symbol_tables(nsym);
  for (uint32_t l = 0; l < considered_.size(); ++l) {
    std::optional<std::vector<uint8_t>>& considered = considered_[l];
    if (!considered) continue;
    // Every module that 'consider:' does not name is ignored; brackets never are.
    considered->resize(nsym, 0);
    std::vector<uint8_t>& ignored = l ? g_.sub_lsystems[l - 1].ignored : g_.ignored;
    for (size_t k = 0; k < nsym; ++k) ignored[k] = k != kSymPush && k != kSymPop && !(*considered)[k];
  }
  if (explicit_pass_ && !pass_has_productions_)
    fail(g_.passes.back().loc, "this pass has no productions");
  for (Grammar::Pass& pass : g_.passes) pass.by_symbol.assign(nsym, {});
  g_.homomorphism_by_symbol.assign(nsym, {});
  g_.decomposition_by_symbol.assign(nsym, {});
  for (uint32_t i = 0; i < g_.decomposition.size(); ++i)
    g_.decomposition_by_symbol[g_.decomposition[i].predecessor.symbol].push_back(i);
  for (uint32_t i = 0; i < g_.productions.size(); ++i)
    g_.passes[g_.productions[i].pass].by_symbol[g_.productions[i].predecessor.symbol].push_back(i);
  for (uint32_t i = 0; i < g_.homomorphism.size(); ++i)
    g_.homomorphism_by_symbol[g_.homomorphism[i].predecessor.symbol].push_back(i);
  for (size_t i = 0; i < g_.axiom.size(); ++i)
    if (g_.axiom.modules[i].symbol == kSymCut) g_.uses_cut = true;
}

Word Parser::parse_word_line(const LogicalLine& line) {
  Successor s = compile_successor(Cursor{&line, 0, line.text.size()}, Scope{}, "the word");
  return s.all_constant ? std::move(s.prebuilt) : evaluate_constant_word(s);
}

}  // namespace

ParseWork& parse_work() {
  thread_local ParseWork work;
  return work;
}

namespace {

// Line `line` (1-based) of `text` without its newline.
std::string_view line_of(const std::string* text, uint32_t line) {
  if (!text || line == 0) return {};
  size_t pos = 0;
  for (uint32_t l = 1; l < line; ++l) {
    pos = text->find('\n', pos);
    if (pos == std::string::npos) return {};
    ++pos;
  }
  size_t end = text->find('\n', pos);
  std::string_view s = std::string_view(*text).substr(pos, end == std::string::npos ? std::string::npos : end - pos);
  // The line ends at its CR too (CRLF, or the lone CR an error points at).
  if (size_t cr = s.find('\r'); cr != std::string_view::npos) s = s.substr(0, cr);
  return s;
}

}  // namespace

std::string_view Grammar::source_line(SourceLoc loc) const {
  if (loc.file > includes.size()) return {};
  return line_of(loc.file == 0 ? text.get() : includes[loc.file - 1].text.get(), loc.line);
}

Diagnostic Grammar::error_at(SourceLoc loc, std::string message) const {
  // One place, in the file `at` names, with its source line.
  auto located = [this](SourceLoc at, std::string text) {
    const bool included = at.file > 0 && at.file <= includes.size();
    Diagnostic d = diagnostic_at(included ? includes[at.file - 1].path : file, {at.line, at.column}, std::move(text));
    if (at.line) set_source_line(d, source_line(at));
    return d;
  };
  Diagnostic d = located(loc, std::move(message));
  // The include chain, innermost first: an includer comes before what it includes in
  // `includes`, so the walk ends.
  for (SourceLoc at = loc; at.file > 0 && at.file <= includes.size();) {
    at = includes[at.file - 1].included_at;
    d = std::move(d).with_note(located(at, "included from here"));
  }
  return d;
}

namespace {

Expected<Grammar> parse_grammar_text(std::shared_ptr<const std::string> text, std::string file,
                                     const ParseOptions& options) {
  Grammar g;
  g.file = std::move(file);
  g.text = std::move(text);
  try {
    Parser parser(g, options);
    parser.parse(*g.text);
  } catch (const ParseFailure& f) {
    return g.error_at(f.loc, f.message);
  }
  return g;
}

}  // namespace

Expected<Grammar> parse_grammar(std::string_view text, std::string file, const ParseOptions& options) {
  return parse_grammar_text(std::make_shared<const std::string>(text), std::move(file), options);
}

Expected<Grammar> load_grammar(const std::string& path, const ParseOptions& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return load_vlab_object(path, options);
  // Bounded, regular files and pipes only (docs/limits.md): a directory is not "no axiom".
  Expected<std::string> text = read_text_file(path);
  if (!text) return std::move(text.error());
  // The text read is the grammar's own (moved, not copied: a 1 GiB file is held once).
  return parse_grammar_text(std::make_shared<const std::string>(std::move(*text)), path, options);
}

Expected<Word> parse_word(std::string_view text, Grammar& grammar) {
  LogicalLine line;
  line.text = std::string(text);
  line.pieces.push_back({0, 1, 1});
  try {
    if (line.text.find('\n') != std::string::npos) fail({1, static_cast<uint32_t>(line.text.find('\n') + 1)}, "a word is one line");
    validate_text(text);
    ParseOptions none;
    Parser parser(grammar, none);
    Word w = parser.parse_word_line(line);
    const size_t nsym = grammar.symbols.size();  // the word may name new modules
    grammar.resize_symbol_tables(nsym);
    for (Grammar::Pass& pass : grammar.passes) pass.by_symbol.resize(nsym);
    grammar.homomorphism_by_symbol.resize(nsym);
    grammar.decomposition_by_symbol.resize(nsym);
    return w;
  } catch (const ParseFailure& f) {
    Diagnostic d = diagnostic_at("<word>", f.loc, f.message);
    if (f.loc.line) set_source_line(d, text);
    return d;
  }
}

}  // namespace sylva::lsys
