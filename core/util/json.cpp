// json.cpp — the strict JSON reader of json.h (RFC 8259) and the writing helpers.
//
// The parser is a loop over an explicit stack of open containers, never recursion, so
// a hostile "[[[[..." costs one stack entry per level up to max_depth and then stops
// with a located error. Numbers are validated against the RFC 8259 grammar before
// std::from_chars converts them, so from_chars never sees anything JSON forbids.
#include "core/util/json.h"

#include <cassert>
#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>
#include <unordered_map>
#include <utility>

namespace sylva {
namespace {

constexpr std::string_view kReplacementCharacter = "\xEF\xBF\xBD";  // U+FFFD

bool in_range(unsigned value, unsigned low, unsigned high) {
  return value >= low && value <= high;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool is_ascii_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

// Length of the well-formed UTF-8 sequence starting at text[pos], or 0 if it is not one.
// Unicode 15, table 3-7: rejects overlong forms, UTF-16 surrogates (ED A0..BF) and code
// points above U+10FFFF (F4 90.. and F5..FF), truncated sequences and stray continuation
// bytes.
size_t utf8_sequence_length(std::string_view text, size_t pos) {
  auto byte = [&](size_t i) -> unsigned {
    return i < text.size() ? static_cast<unsigned char>(text[i]) : 0x100u;
  };
  const unsigned lead = byte(pos);
  if (lead < 0x80) return 1;
  if (in_range(lead, 0xC2, 0xDF)) return in_range(byte(pos + 1), 0x80, 0xBF) ? 2 : 0;
  if (in_range(lead, 0xE0, 0xEF)) {
    const unsigned low = lead == 0xE0 ? 0xA0 : 0x80;
    const unsigned high = lead == 0xED ? 0x9F : 0xBF;
    return in_range(byte(pos + 1), low, high) && in_range(byte(pos + 2), 0x80, 0xBF) ? 3 : 0;
  }
  if (in_range(lead, 0xF0, 0xF4)) {
    const unsigned low = lead == 0xF0 ? 0x90 : 0x80;
    const unsigned high = lead == 0xF4 ? 0x8F : 0xBF;
    return in_range(byte(pos + 1), low, high) && in_range(byte(pos + 2), 0x80, 0xBF) &&
                   in_range(byte(pos + 3), 0x80, 0xBF)
               ? 4
               : 0;
  }
  return 0;
}

void append_utf8(std::string& out, uint32_t code_point) {
  assert(code_point <= 0x10FFFF && !(code_point >= 0xD800 && code_point <= 0xDFFF));
  if (code_point < 0x80) {
    out += static_cast<char>(code_point);
  } else if (code_point < 0x800) {
    out += static_cast<char>(0xC0 | (code_point >> 6));
    out += static_cast<char>(0x80 | (code_point & 0x3F));
  } else if (code_point < 0x10000) {
    out += static_cast<char>(0xE0 | (code_point >> 12));
    out += static_cast<char>(0x80 | ((code_point >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code_point & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (code_point >> 18));
    out += static_cast<char>(0x80 | ((code_point >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((code_point >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code_point & 0x3F));
  }
}

std::string hex_byte(unsigned char byte) {
  constexpr char kDigits[] = "0123456789ABCDEF";
  return std::string("0x") + kDigits[byte >> 4] + kDigits[byte & 0xF];
}

std::string hex_unit(uint32_t unit) {  // "\uD83D"
  constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "\\u";
  for (int shift = 12; shift >= 0; shift -= 4) s += kDigits[(unit >> shift) & 0xF];
  return s;
}

// Places are uint32; a file big enough to overflow one keeps reporting the last value.
uint32_t add_saturating(uint32_t value, size_t amount) {
  const uint64_t sum = uint64_t{value} + amount;
  return sum > std::numeric_limits<uint32_t>::max() ? std::numeric_limits<uint32_t>::max()
                                                    : static_cast<uint32_t>(sum);
}

// An array or object whose closing bracket has not been read yet.
struct OpenContainer {
  JsonValue value;
  // Key -> member index, built once an object is big enough that a linear duplicate
  // check would make a hostile object quadratic.
  std::unordered_map<std::string, size_t> key_index;
};

constexpr size_t kLinearKeyCheckLimit = 8;

class Parser {
 public:
  Parser(std::string_view text, std::string_view file, const JsonParseOptions& options)
      : text_(text), file_(file), options_(options) {}

  Expected<JsonValue> parse();

 private:
  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return text_[pos_]; }

  // Steps over one ASCII character.
  void advance_ascii() {
    if (text_[pos_] == '\n') {
      line_ = add_saturating(line_, 1);
      column_ = 1;
    } else {
      column_ = add_saturating(column_, 1);
    }
    ++pos_;
  }

  // Steps over `count` ASCII characters known to hold no line break.
  void advance_on_line(size_t count) {
    pos_ += count;
    column_ = add_saturating(column_, count);
  }

  void skip_whitespace() {
    while (!at_end()) {
      const char c = peek();
      if (c != ' ' && c != '\t' && c != '\n' && c != '\r') return;
      advance_ascii();
    }
  }

  bool fail(uint32_t line, uint32_t column, std::string message) {
    error_ = diagnostic_at(std::string(file_), {line, column}, std::move(message));
    return false;
  }
  bool fail_here(std::string message) { return fail(line_, column_, std::move(message)); }

  // "expected <what>, found <the character here>", with the usual suspects explained.
  bool fail_unexpected(const std::string& expected) {
    if (at_end()) return fail_here("unexpected end of input; expected " + expected);
    if (peek() == '/' && pos_ + 1 < text_.size() &&
        (text_[pos_ + 1] == '/' || text_[pos_ + 1] == '*')) {
      return fail_here("comments are not allowed in JSON");
    }
    return fail_here("expected " + expected + ", found " + describe_here());
  }

  // The character at pos_, as a message shows it.
  std::string describe_here() const {
    const unsigned char c = static_cast<unsigned char>(peek());
    if (c >= 0x21 && c <= 0x7E) return std::string("'") + static_cast<char>(c) + "'";
    if (c < 0x80) return "control character " + hex_byte(c);
    const size_t length = utf8_sequence_length(text_, pos_);
    if (length == 0) return "byte " + hex_byte(c) + " (not UTF-8)";
    return "'" + std::string(text_.substr(pos_, length)) + "'";
  }

  bool parse_member_key(OpenContainer& object);
  bool parse_scalar(JsonValue& value);
  bool parse_string(std::string& out);
  bool parse_escape(std::string& out);
  bool parse_hex4(uint32_t& unit, uint32_t escape_line, uint32_t escape_column);
  bool parse_number(JsonValue& value);
  bool parse_word(JsonValue& value);

  std::string_view text_;
  std::string_view file_;
  JsonParseOptions options_;
  size_t pos_ = 0;
  uint32_t line_ = 1;
  uint32_t column_ = 1;
  uint64_t values_ = 0;
  std::optional<Diagnostic> error_;
};

Expected<JsonValue> Parser::parse() {
  if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;  // byte order mark, not counted

  std::vector<OpenContainer> open;  // innermost last; size() is the nesting depth
  JsonValue completed;              // the value just read, not yet attached to a parent
  bool have_completed = false;
  for (;;) {
    if (!have_completed) {
      skip_whitespace();
      if (at_end()) {
        fail_here(open.empty() ? "empty input; expected a JSON value"
                               : "unexpected end of input; expected a value");
        break;
      }
      if (++values_ > options_.max_values) {
        fail_here("the document holds more than " + std::to_string(options_.max_values) +
                  " values, the most sylva reads into memory (each takes about 100 bytes)");
        break;
      }
      const char c = peek();
      if (c == '[' || c == '{') {
        if (open.size() >= options_.max_depth) {
          fail_here("arrays and objects are nested more than " +
                    std::to_string(options_.max_depth) + " levels deep");
          break;
        }
        OpenContainer& opened = open.emplace_back();
        opened.value.kind = c == '[' ? JsonValue::Kind::Array : JsonValue::Kind::Object;
        opened.value.line = line_;
        opened.value.column = column_;
        advance_ascii();
        skip_whitespace();
        if (!at_end() && peek() == (c == '[' ? ']' : '}')) {  // empty container
          advance_ascii();
          completed = std::move(opened.value);
          open.pop_back();
          have_completed = true;
          continue;
        }
        if (c == '{' && !parse_member_key(opened)) break;
        continue;  // read the first element or member value
      }
      if (!parse_scalar(completed)) break;
      have_completed = true;
    }

    // A value is complete: it is the root, or belongs to the innermost open container.
    if (open.empty()) {
      skip_whitespace();
      if (!at_end()) {
        fail_unexpected("the end of the input after the JSON value (a JSON text holds one value)");
        break;
      }
      return completed;
    }
    OpenContainer& top = open.back();
    const bool is_array = top.value.kind == JsonValue::Kind::Array;
    if (is_array) {
      top.value.elements.push_back(std::move(completed));
    } else {
      top.value.members.back().value = std::move(completed);
    }
    completed = JsonValue{};
    have_completed = false;

    skip_whitespace();
    const char close = is_array ? ']' : '}';
    if (at_end()) {
      fail_here(std::string("unexpected end of input; the ") + (is_array ? "array" : "object") +
                " opened at line " + std::to_string(top.value.line) + ", column " +
                std::to_string(top.value.column) + " is not closed");
      break;
    }
    if (peek() == ',') {
      const uint32_t comma_line = line_;
      const uint32_t comma_column = column_;
      advance_ascii();
      skip_whitespace();
      if (!at_end() && peek() == close) {
        fail(comma_line, comma_column,
             std::string("trailing comma before '") + close + "' is not allowed in JSON");
        break;
      }
      if (!is_array && !parse_member_key(top)) break;
      continue;
    }
    if (peek() == close) {
      advance_ascii();
      completed = std::move(top.value);
      open.pop_back();
      have_completed = true;
      continue;
    }
    fail_unexpected(is_array ? "',' or ']' after an array element"
                             : "',' or '}' after an object member");
    break;
  }
  assert(error_.has_value());
  return std::move(*error_);
}

// Reads `"key" :` (whitespace skipped before the key already) and opens a member.
bool Parser::parse_member_key(OpenContainer& object) {
  if (at_end() || peek() != '"') {
    if (!at_end() && (is_ascii_letter(peek()) || peek() == '_')) {
      return fail_here("object keys must be strings in double quotes");
    }
    if (!at_end() && peek() == '\'') {
      return fail_here("strings must be in double quotes, not single quotes");
    }
    return fail_unexpected("a string key in double quotes");
  }
  JsonKey key;
  key.line = line_;
  key.column = column_;
  if (!parse_string(key.name)) return false;

  std::vector<JsonMember>& members = object.value.members;
  const JsonKey* first = nullptr;
  if (members.size() < kLinearKeyCheckLimit) {
    for (const JsonMember& member : members) {
      if (member.key.name == key.name) first = &member.key;
    }
  } else {
    if (object.key_index.empty()) {
      for (size_t i = 0; i < members.size(); ++i) object.key_index.emplace(members[i].key.name, i);
    }
    const auto [it, inserted] = object.key_index.emplace(key.name, members.size());
    if (!inserted) first = &members[it->second].key;
  }
  if (first != nullptr) {
    return fail(key.line, key.column,
                "duplicate key " + json_excerpt(key.name) + " (first at line " +
                    std::to_string(first->line) + ", column " + std::to_string(first->column) +
                    ")");
  }

  skip_whitespace();
  if (at_end() || peek() != ':') return fail_unexpected("':' after the key " + json_excerpt(key.name));
  advance_ascii();
  members.push_back(JsonMember{std::move(key), JsonValue{}});
  return true;
}

// A string, number, true, false or null (pos_ is at its first character).
bool Parser::parse_scalar(JsonValue& value) {
  value.line = line_;
  value.column = column_;
  const char c = peek();
  if (c == '"') {
    value.kind = JsonValue::Kind::String;
    return parse_string(value.text);
  }
  if (c == '-' || is_digit(c)) return parse_number(value);
  if (is_ascii_letter(c)) return parse_word(value);
  if (c == '+') return fail_here("a JSON number must not start with '+'");
  if (c == '.') return fail_here("a JSON number must start with a digit (0.5, not .5)");
  if (c == '\'') return fail_here("strings must be in double quotes, not single quotes");
  if (c == ']' || c == '}') return fail_here(std::string("expected a value, found '") + c + "'");
  return fail_unexpected("a value");
}

bool Parser::parse_string(std::string& out) {
  const uint32_t open_line = line_;
  const uint32_t open_column = column_;
  advance_ascii();  // the opening quote
  for (;;) {
    size_t run_end = pos_;  // plain printable ASCII is copied in runs
    while (run_end < text_.size()) {
      const unsigned char c = static_cast<unsigned char>(text_[run_end]);
      if (c == '"' || c == '\\' || c < 0x20 || c >= 0x80) break;
      ++run_end;
    }
    out.append(text_.substr(pos_, run_end - pos_));
    advance_on_line(run_end - pos_);

    if (at_end()) {
      return fail(open_line, open_column,
                  "unterminated string: no closing '\"' before the end of the input");
    }
    const unsigned char c = static_cast<unsigned char>(peek());
    if (c == '"') {
      advance_ascii();
      return true;
    }
    if (c == '\\') {
      if (!parse_escape(out)) return false;
      continue;
    }
    if (c == '\n' || c == '\r') {
      return fail_here("line break inside a string (missing closing '\"'? write a line break as \\n)");
    }
    if (c < 0x20) {
      return fail_here("control character " + hex_byte(c) + " inside a string; escape it as " +
                       hex_unit(c));
    }
    const size_t length = utf8_sequence_length(text_, pos_);
    if (length == 0) return fail_here("invalid UTF-8 (byte " + hex_byte(c) + ") inside a string");
    out.append(text_.substr(pos_, length));
    pos_ += length;
    column_ = add_saturating(column_, 1);  // one code point
  }
}

bool Parser::parse_escape(std::string& out) {
  const uint32_t escape_line = line_;
  const uint32_t escape_column = column_;
  advance_ascii();  // the backslash
  if (at_end()) return fail(escape_line, escape_column, "unterminated escape sequence at the end of the input");
  const char e = peek();
  const char* simple = nullptr;
  switch (e) {
    case '"': simple = "\""; break;
    case '\\': simple = "\\"; break;
    case '/': simple = "/"; break;
    case 'b': simple = "\b"; break;
    case 'f': simple = "\f"; break;
    case 'n': simple = "\n"; break;
    case 'r': simple = "\r"; break;
    case 't': simple = "\t"; break;
    case 'u': break;
    default: {
      const unsigned char byte = static_cast<unsigned char>(e);
      const std::string shown = byte >= 0x21 && byte <= 0x7E ? std::string("'\\") + e + "'"
                                                             : "'\\' followed by " + hex_byte(byte);
      return fail(escape_line, escape_column,
                  "invalid escape " + shown +
                      "; JSON allows \\\" \\\\ \\/ \\b \\f \\n \\r \\t and \\uXXXX");
    }
  }
  if (simple != nullptr) {
    out += simple;
    advance_ascii();
    return true;
  }

  advance_ascii();  // the 'u'
  uint32_t unit = 0;
  if (!parse_hex4(unit, escape_line, escape_column)) return false;
  uint32_t code_point = unit;
  if (unit >= 0xDC00 && unit <= 0xDFFF) {
    return fail(escape_line, escape_column,
                "unpaired low surrogate " + hex_unit(unit) +
                    " (it must follow a high surrogate \\uD800-\\uDBFF)");
  }
  if (unit >= 0xD800 && unit <= 0xDBFF) {
    // UTF-16 surrogate pair: the low half must follow at once (RFC 8259 section 7).
    if (text_.substr(pos_, 2) != "\\u") {
      return fail(escape_line, escape_column,
                  "unpaired high surrogate " + hex_unit(unit) +
                      " (it must be followed by a low surrogate \\uDC00-\\uDFFF)");
    }
    const uint32_t low_line = line_;
    const uint32_t low_column = column_;
    advance_on_line(2);
    uint32_t low = 0;
    if (!parse_hex4(low, low_line, low_column)) return false;
    if (low < 0xDC00 || low > 0xDFFF) {
      return fail(low_line, low_column,
                  "expected a low surrogate \\uDC00-\\uDFFF after the high surrogate " +
                      hex_unit(unit) + ", found " + hex_unit(low));
    }
    code_point = 0x10000 + ((unit - 0xD800) << 10) + (low - 0xDC00);
  }
  append_utf8(out, code_point);
  return true;
}

bool Parser::parse_hex4(uint32_t& unit, uint32_t escape_line, uint32_t escape_column) {
  unit = 0;
  for (int i = 0; i < 4; ++i) {
    const char c = at_end() ? '\0' : peek();
    uint32_t digit = 0;
    if (c >= '0' && c <= '9') {
      digit = static_cast<uint32_t>(c - '0');
    } else if (c >= 'a' && c <= 'f') {
      digit = static_cast<uint32_t>(c - 'a' + 10);
    } else if (c >= 'A' && c <= 'F') {
      digit = static_cast<uint32_t>(c - 'A' + 10);
    } else {
      return fail(escape_line, escape_column, "\\u must be followed by four hex digits");
    }
    unit = unit * 16 + digit;
    advance_ascii();
  }
  return true;
}

// RFC 8259 section 6: -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
bool Parser::parse_number(JsonValue& value) {
  const size_t start = pos_;
  const uint32_t start_column = column_;
  auto digit_at = [&](size_t i) { return i < text_.size() && is_digit(text_[i]); };
  auto fail_at = [&](size_t p, std::string message) {
    return fail(line_, add_saturating(start_column, p - start), std::move(message));
  };

  size_t p = pos_;
  const bool negative = text_[p] == '-';
  if (negative) ++p;
  if (!digit_at(p)) {
    if (p < text_.size() && is_ascii_letter(text_[p])) {
      size_t word_end = p;
      while (word_end < text_.size() && is_ascii_letter(text_[word_end])) ++word_end;
      const std::string_view word = text_.substr(start, word_end - start);
      if (options_.allow_non_finite_numbers && word == "-Infinity") {
        value.kind = JsonValue::Kind::Number;
        value.number = -std::numeric_limits<double>::infinity();
        value.text = word;
        advance_on_line(word.size());
        return true;
      }
      std::string lower(word.substr(1, 16));
      for (char& c : lower) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
      if (lower == "nan" || lower == "inf" || lower == "infinity") {
        return fail_here("'" + std::string(word) +
                         "' is not a JSON number (JSON has no NaN or Infinity)");
      }
    }
    return fail_at(p, "expected a digit after '-'");
  }
  const size_t integer_begin = p;
  if (text_[p] == '0') {
    ++p;
    if (digit_at(p)) return fail_here("leading zeros are not allowed in JSON numbers");
  } else {
    while (digit_at(p)) ++p;
  }
  const size_t integer_end = p;
  size_t fraction_begin = p;
  size_t fraction_end = p;
  if (p < text_.size() && text_[p] == '.') {
    ++p;
    if (!digit_at(p)) return fail_at(p, "expected a digit after the decimal point");
    fraction_begin = p;
    while (digit_at(p)) ++p;
    fraction_end = p;
  }
  int64_t exponent = 0;  // saturates at +-1e9: far beyond any double, no overflow
  if (p < text_.size() && (text_[p] == 'e' || text_[p] == 'E')) {
    ++p;
    bool exponent_negative = false;
    if (p < text_.size() && (text_[p] == '+' || text_[p] == '-')) {
      exponent_negative = text_[p] == '-';
      ++p;
    }
    if (!digit_at(p)) return fail_at(p, "expected a digit in the exponent");
    while (digit_at(p)) {
      if (exponent < 1'000'000'000) exponent = exponent * 10 + (text_[p] - '0');
      ++p;
    }
    if (exponent_negative) exponent = -exponent;
  }

  const std::string_view source = text_.substr(start, p - start);
  double parsed = 0.0;
  const auto [end, error] = std::from_chars(source.data(), source.data() + source.size(), parsed);
  if (error == std::errc::result_out_of_range) {
    // from_chars says "out of range" for both overflow and underflow; tell them apart by
    // the decimal exponent of the leading non-zero digit (>= 0 means |value| >= 1).
    int64_t leading_exponent = -1;
    bool found = false;
    for (size_t i = integer_begin; i < integer_end && !found; ++i) {
      if (text_[i] != '0') {
        leading_exponent = static_cast<int64_t>(integer_end - 1 - i);
        found = true;
      }
    }
    for (size_t i = fraction_begin; i < fraction_end && !found; ++i) {
      if (text_[i] != '0') {
        leading_exponent = -static_cast<int64_t>(i - fraction_begin + 1);
        found = true;
      }
    }
    if (found && leading_exponent + exponent >= 0) {
      if (!options_.allow_non_finite_numbers) {
        return fail_here("number " + std::string(source.substr(0, 40)) +
                         (source.size() > 40 ? "..." : "") +
                         " is out of range of a double (beyond +-1.8e308)");
      }
      parsed = negative ? -std::numeric_limits<double>::infinity()
                        : std::numeric_limits<double>::infinity();
    } else {
      parsed = negative ? -0.0 : 0.0;  // underflow: the correctly rounded result
    }
  } else if (error != std::errc() || end != source.data() + source.size()) {
    assert(false && "from_chars rejected a number the JSON grammar accepts");
    return fail_here("malformed number");
  }
  value.kind = JsonValue::Kind::Number;
  value.number = parsed;
  value.text = source;
  advance_on_line(source.size());
  return true;
}

// true, false, null; and the words people expect JSON to know but it does not.
bool Parser::parse_word(JsonValue& value) {
  size_t end = pos_;
  while (end < text_.size() && (is_ascii_letter(text_[end]) || is_digit(text_[end]) || text_[end] == '_')) {
    ++end;
  }
  const std::string_view word = text_.substr(pos_, end - pos_);
  if (word == "true" || word == "false") {
    value.kind = JsonValue::Kind::Bool;
    value.boolean = word == "true";
  } else if (word == "null") {
    value.kind = JsonValue::Kind::Null;
  } else if (options_.allow_non_finite_numbers && (word == "NaN" || word == "Infinity")) {
    value.kind = JsonValue::Kind::Number;
    value.number = word == "NaN" ? std::numeric_limits<double>::quiet_NaN()
                                 : std::numeric_limits<double>::infinity();
    value.text = word;
  } else {
    std::string lower(word.substr(0, 32));
    for (char& c : lower) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    const std::string shown = "'" + std::string(word.substr(0, 32)) + (word.size() > 32 ? "...'" : "'");
    if (lower == "nan" || lower == "inf" || lower == "infinity") {
      return fail_here(shown + " is not a JSON value (JSON has no NaN or Infinity)");
    }
    if (lower == "true" || lower == "false" || lower == "null") {
      return fail_here(shown + " is not a JSON value (JSON's literals are lower case: " + lower + ")");
    }
    return fail_here("unexpected " + shown +
                     "; expected a value (a string, number, object, array, true, false or null)");
  }
  advance_on_line(word.size());
  return true;
}

}  // namespace

const JsonValue* JsonValue::find(std::string_view key) const {
  for (const JsonMember& member : members) {
    if (member.key.name == key) return &member.value;
  }
  return nullptr;
}

std::optional<uint64_t> JsonValue::as_uint64() const {
  if (kind != Kind::Number || text.empty()) return std::nullopt;
  for (const char c : text) {
    if (!is_digit(c)) return std::nullopt;  // sign, fraction or exponent
  }
  uint64_t result = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), result);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;  // > 2^64-1
  return result;
}

const char* JsonValue::kind_name() const {
  switch (kind) {
    case Kind::Null: return "null";
    case Kind::Bool: return "a boolean";
    case Kind::Number: return "a number";
    case Kind::String: return "a string";
    case Kind::Array: return "an array";
    case Kind::Object: return "an object";
  }
  return "an unknown value";
}

Expected<JsonValue> parse_json(std::string_view text, std::string_view file, const JsonParseOptions& options) {
  return Parser(text, file, options).parse();
}

void append_json_number(std::string& out, double value) {
  assert(std::isfinite(value) && "append_json_number: JSON has no NaN or infinity");
  if (!std::isfinite(value)) {
    out += "null";
    return;
  }
  if (value == 0.0) {  // +0.0 and -0.0 alike
    out += '0';
    return;
  }
  char buffer[32];  // the longest shortest form, "-2.2250738585072014e-308", is 24
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  assert(error == std::errc());
  out.append(buffer, end);
}

void append_json_uint64(std::string& out, uint64_t value) {
  char buffer[24];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  assert(error == std::errc());
  out.append(buffer, end);
}

void append_json_int64(std::string& out, int64_t value) {
  char buffer[24];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  assert(error == std::errc());
  out.append(buffer, end);
}

void append_json_string(std::string& out, std::string_view utf8) {
  out += '"';
  size_t i = 0;
  while (i < utf8.size()) {
    const unsigned char c = static_cast<unsigned char>(utf8[i]);
    if (c >= 0x80) {
      const size_t length = utf8_sequence_length(utf8, i);
      if (length == 0) {
        out += kReplacementCharacter;
        ++i;
      } else {
        out.append(utf8.substr(i, length));
        i += length;
      }
      continue;
    }
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          constexpr char kDigits[] = "0123456789abcdef";
          out += "\\u00";
          out += kDigits[c >> 4];
          out += kDigits[c & 0xF];
        } else {
          out += static_cast<char>(c);
        }
    }
    ++i;
  }
  out += '"';
}

std::string json_excerpt(std::string_view utf8) {
  constexpr size_t kMaxCodePoints = 40;
  size_t end = 0;
  size_t code_points = 0;
  while (end < utf8.size() && code_points < kMaxCodePoints) {
    const size_t length = utf8_sequence_length(utf8, end);
    end += length == 0 ? 1 : length;
    ++code_points;
  }
  std::string out;
  append_json_string(out, utf8.substr(0, end));
  if (end < utf8.size()) out += "...";
  return out;
}

void JsonWriter::before_value(bool is_key) {
  if (open_.empty()) {
    assert(out_.empty() && "JsonWriter: a document holds one value");
    return;
  }
  Open& o = open_.back();
  if (o.object && o.after_key) {  // the member's value follows its key directly
    o.after_key = false;
    return;
  }
  assert((!o.object || is_key) && "JsonWriter: a value in an object needs its key first");
  (void)is_key;
  switch (o.layout) {
    case Layout::compact: if (o.count) out_ += ','; break;
    case Layout::spaced: if (o.count) out_ += ", "; break;
    case Layout::lines:
      out_ += o.count ? ",\n" : "\n";
      out_.append(2 * open_.size(), ' ');
      break;
  }
  ++o.count;
}

JsonWriter& JsonWriter::open(char bracket, bool object, Layout layout) {
  before_value();
  out_ += bracket;
  open_.push_back({layout, object});
  return *this;
}

JsonWriter& JsonWriter::close(char bracket, bool object) {
  assert(!open_.empty() && open_.back().object == object && !open_.back().after_key &&
         "JsonWriter: end does not match the open container");
  (void)object;
  const Open o = open_.back();
  open_.pop_back();
  if (o.layout == Layout::lines && o.count) {
    out_ += '\n';
    out_.append(2 * open_.size(), ' ');
  }
  out_ += bracket;
  return *this;
}

JsonWriter& JsonWriter::begin_object(Layout layout) { return open('{', true, layout); }
JsonWriter& JsonWriter::end_object() { return close('}', true); }
JsonWriter& JsonWriter::begin_array(Layout layout) { return open('[', false, layout); }
JsonWriter& JsonWriter::end_array() { return close(']', false); }

JsonWriter& JsonWriter::key(std::string_view name) {
  assert(!open_.empty() && open_.back().object && !open_.back().after_key &&
         "JsonWriter: a key belongs in an object, before its value");
  before_value(true);
  append_json_string(out_, name);
  out_ += open_.back().layout == Layout::compact ? ":" : ": ";
  open_.back().after_key = true;
  return *this;
}

JsonWriter& JsonWriter::number(double value) {
  before_value();
  append_json_number(out_, value);
  return *this;
}

JsonWriter& JsonWriter::string(std::string_view utf8) {
  before_value();
  append_json_string(out_, utf8);
  return *this;
}

JsonWriter& JsonWriter::boolean(bool value) {
  before_value();
  out_ += value ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::null() {
  before_value();
  out_ += "null";
  return *this;
}

JsonWriter& JsonWriter::raw(std::string_view json) {
  before_value();
  out_ += json;
  return *this;
}

JsonWriter& JsonWriter::numbers(const double* values, size_t count, Layout layout) {
  begin_array(layout);
  for (size_t i = 0; i < count; ++i) number(values[i]);
  return end_array();
}

}  // namespace sylva
