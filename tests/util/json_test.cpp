// Tests for core/util/json.h: the strict located reader, the writing helpers and JsonWriter.
//
// Places are written "line:column", 1-based, columns in code points; the comments over
// the longer inputs show how a column was counted.
#include "core/util/json.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

namespace sylva {
namespace {

using namespace std::string_literals;

JsonValue parse_ok(std::string_view text, const JsonParseOptions& options = {}) {
  Expected<JsonValue> result = parse_json(text, "t.json", options);
  EXPECT_TRUE(result.ok()) << "unexpected error " << result.error().format();
  return result ? std::move(*result) : JsonValue{};
}

// "line:column: message" for the error in `text`, or "no error".
std::string parse_error(std::string_view text, const JsonParseOptions& options = {}) {
  Expected<JsonValue> result = parse_json(text, "t.json", options);
  if (result) return "no error";
  EXPECT_EQ(result.error().file, "t.json");
  EXPECT_FALSE(result.error().source_line.has_value());
  return std::to_string(result.error().loc.line) + ":" + std::to_string(result.error().loc.column) + ": " +
         result.error().message;
}

std::string number_text(double value) {
  std::string out;
  append_json_number(out, value);
  return out;
}

std::string string_text(std::string_view value) {
  std::string out;
  append_json_string(out, value);
  return out;
}

// ---- structure and places -------------------------------------------------------

TEST(JsonRead, EveryValueRecordsTheLineAndColumnWhereItStarts) {
  const JsonValue root = parse_ok(
      "{\"name\": \"fir\",\n"           // "fir" at column 10
      " \"count\": 3,\n"                // 3 at column 11
      " \"ok\": true, \"none\": null,\n"  // true at 8, key "none" at 14, null at 22
      " \"list\": [1, [false], {}]}");  // [ at 10, 1 at 11, [false] at 14, false 15, {} 23
  ASSERT_TRUE(root.is_object());
  EXPECT_EQ(root.line, 1u);
  EXPECT_EQ(root.column, 1u);
  ASSERT_EQ(root.members.size(), 5u);
  EXPECT_EQ(root.members[0].key.name, "name");
  EXPECT_EQ(root.members[0].key.line, 1u);
  EXPECT_EQ(root.members[0].key.column, 2u);
  EXPECT_EQ(root.members[0].value.text, "fir");
  EXPECT_EQ(root.members[0].value.column, 10u);

  const JsonValue* count = root.find("count");
  ASSERT_NE(count, nullptr);
  EXPECT_TRUE(count->is_number());
  EXPECT_EQ(count->number, 3.0);
  EXPECT_EQ(count->line, 2u);
  EXPECT_EQ(count->column, 11u);

  EXPECT_TRUE(root.find("ok")->boolean);
  EXPECT_EQ(root.find("ok")->line, 3u);
  EXPECT_EQ(root.find("ok")->column, 8u);
  EXPECT_EQ(root.members[3].key.column, 14u);
  EXPECT_TRUE(root.find("none")->is_null());
  EXPECT_EQ(root.find("none")->column, 22u);

  const JsonValue& list = *root.find("list");
  ASSERT_TRUE(list.is_array());
  EXPECT_EQ(list.line, 4u);
  EXPECT_EQ(list.column, 10u);
  ASSERT_EQ(list.elements.size(), 3u);
  EXPECT_EQ(list.elements[0].column, 11u);
  ASSERT_TRUE(list.elements[1].is_array());
  EXPECT_EQ(list.elements[1].column, 14u);
  ASSERT_EQ(list.elements[1].elements.size(), 1u);
  EXPECT_FALSE(list.elements[1].elements[0].boolean);
  EXPECT_TRUE(list.elements[1].elements[0].is_bool());
  EXPECT_EQ(list.elements[1].elements[0].column, 15u);
  EXPECT_TRUE(list.elements[2].is_object());
  EXPECT_TRUE(list.elements[2].members.empty());
  EXPECT_EQ(list.elements[2].column, 23u);
}

TEST(JsonRead, ObjectsKeepTheirKeysInSourceOrder) {
  const JsonValue root = parse_ok(R"({"z": 1, "a": 2, "m": 3})");
  ASSERT_EQ(root.members.size(), 3u);
  EXPECT_EQ(root.members[0].key.name, "z");
  EXPECT_EQ(root.members[1].key.name, "a");
  EXPECT_EQ(root.members[2].key.name, "m");
}

TEST(JsonRead, FindReturnsTheMemberOrNullptr) {
  const JsonValue root = parse_ok(R"({"a": 1})");
  ASSERT_NE(root.find("a"), nullptr);
  EXPECT_EQ(root.find("a")->number, 1.0);
  EXPECT_EQ(root.find("b"), nullptr);
  EXPECT_EQ(parse_ok("[1]").find("a"), nullptr);  // not an object
}

TEST(JsonRead, AnyValueMayBeTheRoot) {
  EXPECT_EQ(parse_ok(" 42 ").number, 42.0);
  EXPECT_EQ(parse_ok("\"s\"").text, "s");
  EXPECT_TRUE(parse_ok("null").is_null());
}

TEST(JsonRead, ColumnsCountCodePointsNotBytes) {
  // [ 1, " 2, é 3, € 4, 😀 5, " 6, ',' 7, ' ' 8, 7 at column 9 (12 bytes in).
  const JsonValue root = parse_ok("[\"\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80\", 7]");
  ASSERT_EQ(root.elements.size(), 2u);
  EXPECT_EQ(root.elements[1].column, 9u);
  EXPECT_EQ(parse_error("[\"\xC3\xA9\", \"\xFF\"]"), "1:8: invalid UTF-8 (byte 0xFF) inside a string");
}

TEST(JsonRead, CrLfLineEndingsCountOneLineEach) {
  const JsonValue root = parse_ok("[1,\r\n 2,\r\n  3]");
  EXPECT_EQ(root.elements[1].line, 2u);
  EXPECT_EQ(root.elements[1].column, 2u);
  EXPECT_EQ(root.elements[2].line, 3u);
  EXPECT_EQ(root.elements[2].column, 3u);
}

TEST(JsonRead, ALeadingByteOrderMarkIsSkippedAndNotCounted) {
  const JsonValue root = parse_ok("\xEF\xBB\xBF[1]");
  EXPECT_EQ(root.column, 1u);
  EXPECT_EQ(root.elements[0].column, 2u);
}

// ---- strictness -----------------------------------------------------------------

TEST(JsonRead, RejectsADuplicateKeyAtItsSecondOccurrence) {
  EXPECT_EQ(parse_error(R"({"a": 1, "b": 2, "a": 3})"),
            "1:18: duplicate key \"a\" (first at line 1, column 2)");
}

TEST(JsonRead, RejectsADuplicateKeyInALargeObject) {
  std::string text = "{\n";  // key k<i> on line i + 2
  for (int i = 0; i < 20; ++i) text += "\"k" + std::to_string(i) + "\": " + std::to_string(i) + ",\n";
  text += "\"k7\": 7\n}";
  EXPECT_EQ(parse_error(text), "22:1: duplicate key \"k7\" (first at line 9, column 1)");
  const JsonValue unique = parse_ok("{\"k0\":0,\"k1\":1,\"k2\":2,\"k3\":3,\"k4\":4,\"k5\":5,"
                                    "\"k6\":6,\"k7\":7,\"k8\":8,\"k9\":9,\"k10\":10}");
  EXPECT_EQ(unique.members.size(), 11u);
  EXPECT_EQ(unique.find("k10")->number, 10.0);
}

TEST(JsonRead, RejectsCommentsWhereverTheyAppear) {
  EXPECT_EQ(parse_error("[1, // two\n 2]"), "1:5: comments are not allowed in JSON");
  EXPECT_EQ(parse_error("/* c */ [1]"), "1:1: comments are not allowed in JSON");
  EXPECT_EQ(parse_error("[1] // end"), "1:5: comments are not allowed in JSON");
  EXPECT_EQ(parse_error("[1 /* c */]"), "1:4: comments are not allowed in JSON");
}

TEST(JsonRead, RejectsTrailingCommasAtTheComma) {
  EXPECT_EQ(parse_error("[1, 2,]"), "1:6: trailing comma before ']' is not allowed in JSON");
  EXPECT_EQ(parse_error("{\"a\": 1,\n}"), "1:8: trailing comma before '}' is not allowed in JSON");
  EXPECT_EQ(parse_error("[,1]"), "1:2: expected a value, found ','");
  EXPECT_EQ(parse_error("[1,,2]"), "1:4: expected a value, found ','");
}

TEST(JsonRead, RejectsNaNAndInfinityByName) {
  EXPECT_EQ(parse_error("[1, NaN]"), "1:5: 'NaN' is not a JSON value (JSON has no NaN or Infinity)");
  EXPECT_EQ(parse_error("Infinity"),
            "1:1: 'Infinity' is not a JSON value (JSON has no NaN or Infinity)");
  EXPECT_EQ(parse_error("[-Infinity]"),
            "1:2: '-Infinity' is not a JSON number (JSON has no NaN or Infinity)");
  EXPECT_EQ(parse_error("[nan]"), "1:2: 'nan' is not a JSON value (JSON has no NaN or Infinity)");
  EXPECT_EQ(parse_error("[-inf]"), "1:2: '-inf' is not a JSON number (JSON has no NaN or Infinity)");
}

TEST(JsonRead, NonFiniteNumbersAreValuesOnlyWhenAskedFor) {
  JsonParseOptions options;
  options.allow_non_finite_numbers = true;
  const JsonValue root = parse_ok("[NaN, Infinity, -Infinity, 1e400, -1e400]", options);
  ASSERT_EQ(root.elements.size(), 5u);
  for (const JsonValue& element : root.elements) EXPECT_TRUE(element.is_number());
  EXPECT_TRUE(std::isnan(root.elements[0].number));
  EXPECT_EQ(root.elements[1].number, std::numeric_limits<double>::infinity());
  EXPECT_EQ(root.elements[2].number, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(root.elements[3].number, std::numeric_limits<double>::infinity());
  EXPECT_EQ(root.elements[3].text, "1e400");
  EXPECT_EQ(root.elements[4].number, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(root.elements[2].text, "-Infinity");
  // Only the spellings other writers produce; "nan" stays an error.
  EXPECT_EQ(parse_error("[nan]", options),
            "1:2: 'nan' is not a JSON value (JSON has no NaN or Infinity)");
}

TEST(JsonRead, ANumberThatOverflowsADoubleIsAnError) {
  EXPECT_EQ(parse_error("[1e400]"), "1:2: number 1e400 is out of range of a double (beyond +-1.8e308)");
  EXPECT_EQ(parse_error("[-1e400]"), "1:2: number -1e400 is out of range of a double (beyond +-1.8e308)");
  EXPECT_EQ(parse_error("1.7976931348623159e308"),
            "1:1: number 1.7976931348623159e308 is out of range of a double (beyond +-1.8e308)");
  EXPECT_EQ(parse_error("10e308"), "1:1: number 10e308 is out of range of a double (beyond +-1.8e308)");
  EXPECT_EQ(parse_error("1e99999999999999999999"),
            "1:1: number 1e99999999999999999999 is out of range of a double (beyond +-1.8e308)");
  EXPECT_EQ(parse_error(std::string(400, '9')),
            "1:1: number " + std::string(40, '9') +
                "... is out of range of a double (beyond +-1.8e308)");
  EXPECT_EQ(parse_ok("1.7976931348623157e308").number, std::numeric_limits<double>::max());
  EXPECT_EQ(parse_ok("0.0001e312").number, 1e308);
}

TEST(JsonRead, ANumberThatUnderflowsReadsAsZeroOfItsSign) {
  const JsonValue positive = parse_ok("1e-400");
  EXPECT_EQ(positive.number, 0.0);
  EXPECT_FALSE(std::signbit(positive.number));
  const JsonValue negative = parse_ok("-1e-400");
  EXPECT_EQ(negative.number, 0.0);
  EXPECT_TRUE(std::signbit(negative.number));
  EXPECT_EQ(parse_ok("1e-99999999999999999999").number, 0.0);
  EXPECT_EQ(parse_ok("4.9406564584124654e-324").number, std::numeric_limits<double>::denorm_min());
}

TEST(JsonRead, RejectsNumbersOutsideTheJsonGrammar) {
  EXPECT_EQ(parse_error("01"), "1:1: leading zeros are not allowed in JSON numbers");
  EXPECT_EQ(parse_error("[-007]"), "1:2: leading zeros are not allowed in JSON numbers");
  EXPECT_EQ(parse_error("[+1]"), "1:2: a JSON number must not start with '+'");
  EXPECT_EQ(parse_error("[.5]"), "1:2: a JSON number must start with a digit (0.5, not .5)");
  EXPECT_EQ(parse_error("[1.]"), "1:4: expected a digit after the decimal point");
  EXPECT_EQ(parse_error("[1.e5]"), "1:4: expected a digit after the decimal point");
  EXPECT_EQ(parse_error("[1e]"), "1:4: expected a digit in the exponent");
  EXPECT_EQ(parse_error("[1e+]"), "1:5: expected a digit in the exponent");
  EXPECT_EQ(parse_error("[-]"), "1:3: expected a digit after '-'");
  EXPECT_EQ(parse_error("[0x1F]"), "1:3: expected ',' or ']' after an array element, found 'x'");
}

TEST(JsonRead, NumbersKeepTheirExactSourceText) {
  const JsonValue number = parse_ok("-0.50e3");
  EXPECT_EQ(number.text, "-0.50e3");
  EXPECT_EQ(number.number, -500.0);
  const JsonValue negative_zero = parse_ok("-0");
  EXPECT_EQ(negative_zero.text, "-0");
  EXPECT_TRUE(std::signbit(negative_zero.number));
  EXPECT_EQ(parse_ok("123456789012345678").number, 123456789012345680.0);
}

TEST(JsonRead, AsUint64ReadsPlainIntegersExactlyAndNothingElse) {
  EXPECT_EQ(parse_ok("18446744073709551615").as_uint64(), std::optional<uint64_t>(UINT64_MAX));
  EXPECT_EQ(parse_ok("9007199254740993").as_uint64(), std::optional<uint64_t>(9007199254740993u));
  EXPECT_EQ(parse_ok("0").as_uint64(), std::optional<uint64_t>(0));
  EXPECT_EQ(parse_ok("18446744073709551616").as_uint64(), std::nullopt);  // overflow
  EXPECT_EQ(parse_ok("1.0").as_uint64(), std::nullopt);                   // fraction
  EXPECT_EQ(parse_ok("1e2").as_uint64(), std::nullopt);                   // exponent
  EXPECT_EQ(parse_ok("-1").as_uint64(), std::nullopt);                    // negative
  EXPECT_EQ(parse_ok("-0").as_uint64(), std::nullopt);                    // a sign
  EXPECT_EQ(parse_ok("\"7\"").as_uint64(), std::nullopt);                 // a string
}

TEST(JsonRead, RejectsLiteralsThatAreNotJson) {
  EXPECT_EQ(parse_error("True"), "1:1: 'True' is not a JSON value (JSON's literals are lower case: true)");
  EXPECT_EQ(parse_error("[truex]"),
            "1:2: unexpected 'truex'; expected a value (a string, number, object, array, true, "
            "false or null)");
  EXPECT_EQ(parse_error("['a']"), "1:2: strings must be in double quotes, not single quotes");
  EXPECT_EQ(parse_error("{a: 1}"), "1:2: object keys must be strings in double quotes");
  EXPECT_EQ(parse_error("{1: 1}"), "1:2: expected a string key in double quotes, found '1'");
  EXPECT_EQ(parse_error("[\xFF]"), "1:2: expected a value, found byte 0xFF (not UTF-8)");
}

TEST(JsonRead, ReportsMissingPunctuationAtTheOffendingCharacter) {
  EXPECT_EQ(parse_error("{\"a\" 1}"), "1:6: expected ':' after the key \"a\", found '1'");
  EXPECT_EQ(parse_error("[1 2]"), "1:4: expected ',' or ']' after an array element, found '2'");
  EXPECT_EQ(parse_error("{\"a\": 1 \"b\": 2}"),
            "1:9: expected ',' or '}' after an object member, found '\"'");
  EXPECT_EQ(parse_error("[1] [2]"),
            "1:5: expected the end of the input after the JSON value (a JSON text holds one "
            "value), found '['");
}

TEST(JsonRead, ReportsTheEndOfInputAndWhatIsStillOpen) {
  EXPECT_EQ(parse_error(""), "1:1: empty input; expected a JSON value");
  EXPECT_EQ(parse_error("  \n "), "2:2: empty input; expected a JSON value");
  EXPECT_EQ(parse_error("[1, 2"), "1:6: unexpected end of input; the array opened at line 1, column 1 is not closed");
  EXPECT_EQ(parse_error("{\"a\": [1]\n"),
            "2:1: unexpected end of input; the object opened at line 1, column 1 is not closed");
  EXPECT_EQ(parse_error("{\"a\":"), "1:6: unexpected end of input; expected a value");
  EXPECT_EQ(parse_error("[\"abc"), "1:2: unterminated string: no closing '\"' before the end of the input");
}

// ---- nesting ----------------------------------------------------------------------

TEST(JsonRead, AMillionOpenBracketsIsALocatedErrorNotACrash) {
  const std::string text(1'000'000, '[');
  EXPECT_EQ(parse_error(text), "1:257: arrays and objects are nested more than 256 levels deep");
}

TEST(JsonRead, DeeplyNestedObjectsAreLimitedToo) {
  std::string text;
  for (int i = 0; i < 100'000; ++i) text += "{\"a\":";  // level k opens at column 5(k-1)+1
  EXPECT_EQ(parse_error(text), "1:1281: arrays and objects are nested more than 256 levels deep");
}

TEST(JsonRead, NestingUpToTheLimitIsAccepted) {
  const std::string text = std::string(256, '[') + std::string(256, ']');
  const JsonValue root = parse_ok(text);
  const JsonValue* value = &root;
  int depth = 1;
  while (!value->elements.empty()) {
    value = &value->elements[0];
    ++depth;
  }
  EXPECT_EQ(depth, 256);
}

TEST(JsonRead, TheDepthLimitIsAnOption) {
  JsonParseOptions options;
  options.max_depth = 2;
  EXPECT_EQ(parse_error("[[[]]]", options), "1:3: arrays and objects are nested more than 2 levels deep");
  EXPECT_EQ(parse_error("[[1]]", options), "no error");
}

TEST(JsonRead, TheValueCountIsBoundedBeforeTheValuesTakeMemory) {
  // A DOM value costs ~100 bytes however short its text: a document of many small values
  // is refused at the first value past the limit (5 values here: the array and 4 numbers).
  JsonParseOptions options;
  options.max_values = 5;
  EXPECT_EQ(parse_error("[1,2,3,4]", options), "no error");
  EXPECT_EQ(parse_error("[1,2,3,4,5]", options),
            "1:10: the document holds more than 5 values, the most sylva reads into memory (each takes about 100 bytes)");
  EXPECT_EQ(parse_error(R"({"a":{"b":[1,2]}})", options), "no error");
  EXPECT_EQ(JsonParseOptions{}.max_values, 50'000'000u);
}

// ---- strings ----------------------------------------------------------------------

TEST(JsonRead, DecodesEveryEscapeIncludingSurrogatePairsToUtf8) {
  const JsonValue value =
      parse_ok(R"("a\"b\\c\/d\b\f\n\r\t\u00e9\u20AC\uD83D\uDE00\u0000z")");
  EXPECT_EQ(value.text, "a\"b\\c/d\b\f\n\r\t\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80\0z"s);
}

TEST(JsonRead, KeepsRawUtf8InStrings) {
  EXPECT_EQ(parse_ok("\"\xC3\xA9\xE2\x82\xAC\xF4\x8F\xBF\xBF\"").text,
            "\xC3\xA9\xE2\x82\xAC\xF4\x8F\xBF\xBF");  // é € U+10FFFF
}

TEST(JsonRead, RejectsUnpairedSurrogatesAndBadEscapes) {
  EXPECT_EQ(parse_error(R"(["\uD83D"])"),
            "1:3: unpaired high surrogate \\uD83D (it must be followed by a low surrogate "
            "\\uDC00-\\uDFFF)");
  EXPECT_EQ(parse_error(R"(["\uDE00"])"),
            "1:3: unpaired low surrogate \\uDE00 (it must follow a high surrogate \\uD800-\\uDBFF)");
  // The second escape starts at column 9: [ " \ u D 8 3 D \.
  EXPECT_EQ(parse_error(R"(["\uD83D\u0041"])"),
            "1:9: expected a low surrogate \\uDC00-\\uDFFF after the high surrogate \\uD83D, "
            "found \\u0041");
  EXPECT_EQ(parse_error(R"(["\u12G4"])"), "1:3: \\u must be followed by four hex digits");
  EXPECT_EQ(parse_error(R"(["\x"])"),
            "1:3: invalid escape '\\x'; JSON allows \\\" \\\\ \\/ \\b \\f \\n \\r \\t and \\uXXXX");
}

TEST(JsonRead, RejectsRawControlCharactersInStrings) {
  EXPECT_EQ(parse_error("[\"a\tb\"]"), "1:4: control character 0x09 inside a string; escape it as \\u0009");
  EXPECT_EQ(parse_error("[\"ab\ncd\"]"),
            "1:5: line break inside a string (missing closing '\"'? write a line break as \\n)");
  EXPECT_EQ(parse_error("[\"a\0b\"]"s), "1:4: control character 0x00 inside a string; escape it as \\u0000");
}

TEST(JsonRead, RejectsInvalidUtf8AtTheFirstBadByte) {
  const struct {
    std::string bytes;
    const char* why;
  } cases[] = {
      {"\xC0\x80", "overlong encoding of U+0000"},
      {"\xE0\x80\xAF", "overlong three-byte form"},
      {"\x80", "continuation byte without a lead"},
      {"\xED\xA0\x80", "UTF-16 surrogate encoded in UTF-8"},
      {"\xF4\x90\x80\x80", "above U+10FFFF"},
      {"\xF5\x80\x80\x80", "lead byte that never occurs"},
      {"\xE2\x82", "truncated sequence"},
      {"\xFF", "never valid"},
  };
  for (const auto& c : cases) {
    const unsigned lead = static_cast<unsigned char>(c.bytes[0]);
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", lead);
    EXPECT_EQ(parse_error("[\"a" + c.bytes + "\"]"),
              "1:4: invalid UTF-8 (byte " + std::string(hex) + ") inside a string")
        << c.why;
  }
}

// ---- writing ----------------------------------------------------------------------

TEST(JsonWrite, NumbersUseTheShortestTextThatReadsBackExactly) {
  EXPECT_EQ(number_text(0.1), "0.1");
  EXPECT_EQ(number_text(1e-300), "1e-300");
  EXPECT_EQ(number_text(1e300), "1e+300");
  EXPECT_EQ(number_text(123456789012345678.0), "123456789012345680");
  EXPECT_EQ(number_text(1.0), "1");
  EXPECT_EQ(number_text(-2.5), "-2.5");
  EXPECT_EQ(number_text(100.0), "100");
  EXPECT_EQ(number_text(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(number_text(std::numeric_limits<double>::denorm_min()), "5e-324");
  EXPECT_EQ(number_text(std::numeric_limits<double>::max()), "1.7976931348623157e+308");
  EXPECT_EQ(number_text(-std::numeric_limits<double>::max()), "-1.7976931348623157e+308");
}

TEST(JsonWrite, NegativeZeroIsWrittenAsZero) {
  EXPECT_EQ(number_text(-0.0), "0");
  EXPECT_EQ(number_text(0.0), "0");
}

TEST(JsonWrite, EveryFiniteDoubleReadsBackBitForBit) {
  std::mt19937_64 random(20240601);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const double value = std::bit_cast<double>(random());
    if (!std::isfinite(value) || value == 0.0) continue;
    const std::string text = number_text(value);
    const JsonValue read = parse_ok(text);
    ASSERT_EQ(std::bit_cast<uint64_t>(read.number), std::bit_cast<uint64_t>(value)) << text;
    ++checked;
  }
  EXPECT_GT(checked, 19000);
}

#ifndef NDEBUG
TEST(JsonWriteDeathTest, WritingANonFiniteNumberIsAProgrammingError) {
  std::string out;
  EXPECT_DEATH(append_json_number(out, std::numeric_limits<double>::quiet_NaN()), "JSON has no NaN");
  EXPECT_DEATH(append_json_number(out, std::numeric_limits<double>::infinity()), "JSON has no NaN");
}
#endif

TEST(JsonWrite, IntegersAreWrittenExactly) {
  std::string out;
  append_json_uint64(out, UINT64_MAX);
  out += ' ';
  append_json_int64(out, INT64_MIN);
  EXPECT_EQ(out, "18446744073709551615 -9223372036854775808");
}

TEST(JsonWrite, StringsEscapeQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(string_text("a\"b\\c/\b\f\n\r\t\x01\x1f\x7f\xC3\xA9"),
            "\"a\\\"b\\\\c/\\b\\f\\n\\r\\t\\u0001\\u001f\x7f\xC3\xA9\"");
  EXPECT_EQ(string_text("nul\0!"s), "\"nul\\u0000!\"");
}

TEST(JsonWrite, InvalidUtf8BytesBecomeReplacementCharacters) {
  EXPECT_EQ(string_text("a\xFF" "b\xC3"), "\"a\xEF\xBF\xBD" "b\xEF\xBF\xBD\"");
  EXPECT_EQ(parse_ok(string_text("\xED\xA0\x80")).text, "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");
}

TEST(JsonWrite, EveryValidStringReadsBackUnchanged) {
  std::string all;
  for (int c = 0; c < 128; ++c) all += static_cast<char>(c);
  all += "\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80\xF4\x8F\xBF\xBF";
  EXPECT_EQ(parse_ok(string_text(all)).text, all);
}

TEST(JsonWrite, ExcerptsAreQuotedAndCutAfterFortyCodePoints) {
  EXPECT_EQ(json_excerpt("key"), "\"key\"");
  EXPECT_EQ(json_excerpt(std::string(50, 'x')), "\"" + std::string(40, 'x') + "\"...");
  std::string accents;
  for (int i = 0; i < 41; ++i) accents += "\xC3\xA9";
  std::string expected = "\"";
  for (int i = 0; i < 40; ++i) expected += "\xC3\xA9";
  EXPECT_EQ(json_excerpt(accents), expected + "\"...");
}

// ---- JsonWriter ----------------------------------------------------------------------

TEST(JsonWriter, CompactLayoutHasNoSpaces) {
  JsonWriter w;
  w.begin_object().key("a").integer(1).key("b").begin_array().number(0.5).string("x").boolean(true).null();
  w.end_array().key("c").begin_object().end_object().end_object();
  EXPECT_EQ(w.text(), R"({"a":1,"b":[0.5,"x",true,null],"c":{}})");
}

TEST(JsonWriter, SpacedLayoutPutsASpaceAfterEachSeparator) {
  JsonWriter w;
  w.begin_object(JsonWriter::Layout::spaced).key("a").integer(1).key("v");
  const double v[3] = {1, -2.5, 1e300};
  w.numbers(v, 3, JsonWriter::Layout::spaced).end_object();
  EXPECT_EQ(w.text(), R"({"a": 1, "v": [1, -2.5, 1e+300]})");
}

TEST(JsonWriter, LinesLayoutIndentsTwoSpacesPerOpenContainer) {
  JsonWriter w;
  w.begin_object(JsonWriter::Layout::lines).key("k").string("v").key("list").begin_array(JsonWriter::Layout::lines);
  w.begin_array().integer(1).integer(2).end_array().begin_object(JsonWriter::Layout::spaced).end_object();
  w.end_array().key("empty").begin_array(JsonWriter::Layout::lines).end_array().end_object();
  EXPECT_EQ(w.text(), "{\n  \"k\": \"v\",\n  \"list\": [\n    [1,2],\n    {}\n  ],\n  \"empty\": []\n}");
}

TEST(JsonWriter, NumbersAndIntegersUseTheByteStableForms) {
  JsonWriter w;
  w.begin_array().number(-0.0).number(0.1).integer(uint64_t{18446744073709551615u}).integer(int64_t{-5});
  w.integer(uint32_t{7}).integer(-3).end_array();
  EXPECT_EQ(w.text(), "[0,0.1,18446744073709551615,-5,7,-3]");
}

TEST(JsonWriter, KeysAndStringsAreEscaped) {
  JsonWriter w;
  w.begin_object().key("a\"b").string("line\nbreak").end_object();
  EXPECT_EQ(w.text(), R"({"a\"b":"line\nbreak"})");
}

TEST(JsonWriter, RawInsertsAValueWrittenElsewhere) {
  JsonWriter inner;
  inner.begin_object().key("x").integer(1).end_object();
  JsonWriter w;
  w.begin_array().raw(inner.text()).raw(inner.text()).end_array();
  EXPECT_EQ(w.take(), R"([{"x":1},{"x":1}])");
}

TEST(JsonWriter, WhatItWritesReadsBack) {
  JsonWriter w;
  w.begin_object(JsonWriter::Layout::lines).key("n").number(0.1 + 0.2).key("s").string("\xC3\xA9\t");
  w.key("a").begin_array(JsonWriter::Layout::spaced).integer(1).begin_object().key("k").null().end_object();
  w.end_array().end_object();
  const JsonValue v = parse_ok(w.text());
  EXPECT_EQ(v.find("n")->number, 0.1 + 0.2);
  EXPECT_EQ(v.find("s")->text, "\xC3\xA9\t");
  ASSERT_EQ(v.find("a")->elements.size(), 2u);
  EXPECT_TRUE(v.find("a")->elements[1].find("k")->is_null());
}

}  // namespace
}  // namespace sylva
