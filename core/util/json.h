// json.h — a small, strict JSON reader (RFC 8259) whose values know where they came
// from, and the writer every sylva document is written with (skeletons, scenes, glTF).
//
// Reading: parse_json builds a DOM in which every value records the 1-based line and
// column of its first character, so a schema check (a skeleton, a scene) can report
// "file:line:column". The parser is strict: no comments, no trailing commas, no NaN or
// Infinity, no leading zeros, no raw control characters or invalid UTF-8 in strings, no
// duplicate keys, no number that overflows a double. It is iterative (an explicit stack
// of open containers), and nesting deeper than JsonParseOptions::max_depth is a located
// error, so a hostile file cannot exhaust the call stack.
//
// Places: lines end at '\n' (so "\r\n" files count right too); columns count Unicode
// code points from the start of the line, a tab being one column. A leading UTF-8 byte
// order mark is skipped (RFC 8259 section 8.1 allows it) and not counted.
//
// Memory: a value takes about 100 bytes (plus its text beyond 15 bytes), so a DOM is
// 10-50 times the size of compact JSON text: a skeleton joint, six values, costs under
// 1 KB while its file is read.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/util/diagnostic.h"

namespace sylva {

// Nesting deeper than this many arrays/objects is rejected by default.
inline constexpr uint32_t kJsonDefaultMaxDepth = 256;
// Values one document may hold (docs/limits.md "Inputs"): a value of the DOM takes about
// 100 bytes however short its text ("0,": 2 bytes), so a 1 GiB file of small numbers would
// otherwise take ~50 GiB. 50 million values are about 5 GiB.
inline constexpr uint64_t kJsonDefaultMaxValues = 50'000'000;

// The key of an object member, with the place of its opening quote.
struct JsonKey {
  std::string name;     // decoded UTF-8; may contain U+0000 if the text escaped it
  uint32_t line = 0;    // 1-based
  uint32_t column = 0;  // 1-based, in code points
};

struct JsonMember;

// One JSON value and where it starts in the source text.
struct JsonValue {
  enum class Kind : uint8_t { Null, Bool, Number, String, Array, Object };

  Kind kind = Kind::Null;
  bool boolean = false;  // Bool: the value
  uint32_t line = 0;     // 1-based line of the value's first character
  uint32_t column = 0;   // 1-based column (code points) of the value's first character
  double number = 0.0;   // Number: the nearest double; finite unless the parse allowed
                         //   non-finite numbers (JsonParseOptions::allow_non_finite_numbers)
  std::string text;      // String: the decoded UTF-8. Number: the exact source text
                         //   ("-0.50e3"), so integers beyond 2^53 can be read exactly
  std::vector<JsonValue> elements;  // Array: the elements, in order
  std::vector<JsonMember> members;  // Object: the members, in source order, keys unique

  bool is_null() const { return kind == Kind::Null; }
  bool is_bool() const { return kind == Kind::Bool; }
  bool is_number() const { return kind == Kind::Number; }
  bool is_string() const { return kind == Kind::String; }
  bool is_array() const { return kind == Kind::Array; }
  bool is_object() const { return kind == Kind::Object; }

  // Object: the value of member `key`, or nullptr if absent (or if this is no object).
  const JsonValue* find(std::string_view key) const;

  // Number written as a plain non-negative integer ("0", "18446744073709551615"): its
  // exact value. nullopt for anything else: not a number, a sign, a fraction or an
  // exponent (even "1.0" or "1e2"), or a value above 2^64 - 1.
  std::optional<uint64_t> as_uint64() const;

  // For messages: "null", "a boolean", "a number", "a string", "an array", "an object".
  const char* kind_name() const;
};

// One member of an object.
struct JsonMember {
  JsonKey key;
  JsonValue value;
};

struct JsonParseOptions {
  // Arrays/objects nested deeper than this are an error (located at the opening bracket).
  // Keep it modest: destroying a DOM recurses once per level.
  uint32_t max_depth = kJsonDefaultMaxDepth;
  // More values than this are an error at the first value past it, before its memory.
  uint64_t max_values = kJsonDefaultMaxValues;
  // When true, the tokens NaN, Infinity and -Infinity and numbers that overflow a double
  // (1e400) become Number values holding NaN/±infinity (text keeps the source), so a
  // schema checker can reject them with a message that names their place in the schema
  // ("chain 2, joint 5: radius ..."). Never true for plain parsing: they are not JSON.
  bool allow_non_finite_numbers = false;
};

// Parses one JSON text (any value at the root, surrounded by optional whitespace).
// Numbers that underflow a double read as zero of the same sign (correct rounding).
// The error is the first problem in the text: a Diagnostic naming `file`, with the line
// and column (code points) of the problem and a one-sentence message without the place
// ("trailing comma before ']' is not allowed in JSON"); no source line.
Expected<JsonValue> parse_json(std::string_view text, std::string_view file = {},
                               const JsonParseOptions& options = {});

// Appends the shortest decimal that reads back to exactly `value` (std::to_chars):
// integers as "1" not "1.0", large/small values with an exponent ("1e+300"), and -0.0
// as "0" (the sign of zero carries no meaning in sylva files, and writing it would make
// files differ for computations that agree). Precondition: `value` is finite (asserted;
// with assertions off a non-finite value writes "null", which readers reject).
void append_json_number(std::string& out, double value);

// Appends an integer exactly, never through a double (seeds, counts, indices).
void append_json_uint64(std::string& out, uint64_t value);
void append_json_int64(std::string& out, int64_t value);

// Appends `utf8` as a quoted JSON string: '"' and '\\' escaped, control characters as
// \n, \t, ... or \u00XX, everything else raw. Bytes that are not valid UTF-8 (a path
// from a non-UTF-8 file system) are each replaced by U+FFFD, so the output is always
// valid JSON.
void append_json_string(std::string& out, std::string_view utf8);

// For error messages: `utf8` quoted as by append_json_string, cut after 40 code points
// with "..." after the closing quote, so a hostile megabyte-long key stays readable.
std::string json_excerpt(std::string_view utf8);

// Writes JSON text value by value with the number, integer and string forms above, so no
// writer formats JSON by hand and every document gets the same byte-stable numbers.
// Each array and object is laid out one of three ways, chosen where it is opened:
//   compact  [1,2] {"a":1}
//   spaced   [1, 2] {"a": 1}
//   lines    one element or member per line, indented two spaces per open container,
//            the closing bracket on its own line ("[]" / "{}" when empty)
// so a document can be pretty at the top and dense in its long arrays (docs/spec/skeleton.md's
// joints). Usage errors (a value without key in an object, unbalanced ends) are asserted.
class JsonWriter {
 public:
  enum class Layout : uint8_t { compact, spaced, lines };

  JsonWriter& begin_object(Layout layout = Layout::compact);
  JsonWriter& end_object();
  JsonWriter& begin_array(Layout layout = Layout::compact);
  JsonWriter& end_array();
  // The key of the next member of the open object (append_json_string).
  JsonWriter& key(std::string_view name);

  JsonWriter& number(double value);  // append_json_number: shortest round trip, finite
  template <class Integer>
  JsonWriter& integer(Integer value) {  // exact, never through a double
    static_assert(std::is_integral_v<Integer> && !std::is_same_v<Integer, bool>);
    before_value();
    if constexpr (std::is_signed_v<Integer>) append_json_int64(out_, value);
    else append_json_uint64(out_, value);
    return *this;
  }
  JsonWriter& string(std::string_view utf8);  // append_json_string
  JsonWriter& boolean(bool value);
  JsonWriter& null();
  // A value that is already JSON text (written by another JsonWriter), copied as it is.
  JsonWriter& raw(std::string_view json);
  // An array of numbers in `layout` (a vector, a colour, a min/max).
  JsonWriter& numbers(const double* values, size_t count, Layout layout = Layout::compact);

  const std::string& text() const { return out_; }  // what is written so far
  std::string take() { return std::move(out_); }   // the text; the writer is spent

 private:
  struct Open {
    Layout layout;
    bool object;
    size_t count = 0;        // elements or members written
    bool after_key = false;  // object: a key was written, its value comes next
  };
  void before_value(bool is_key = false);  // the separator (and indentation) before a value or key
  JsonWriter& open(char bracket, bool object, Layout layout);
  JsonWriter& close(char bracket, bool object);

  std::string out_;
  std::vector<Open> open_;
};

}  // namespace sylva
