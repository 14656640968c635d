// malformed_test.cpp — `sylva derive` on grammars with one mistake each
// (docs/spec/grammar.md "Limits and errors", docs/spec/cli.md): the mistake is reported on stderr as
//   FILE:LINE:COLUMN: error: MESSAGE
//   <the source line>
//   <a caret under the column>
// with exit status 1 and nothing on stdout; never a crash, a hang or a partial word.
//
// The corpus is tests/grammars/malformed/NN_name.lsys (and NN_name.l, cpfg model files,
// docs/cpfg.md); the first line of each file says what to expect:
//   # expect: LINE:COLUMN KEYWORD[|KEYWORD...]   (any one keyword, case-insensitive)
//   # also: TEXT                                 (optional, repeatable: TEXT appears in
//                                                 the message, e.g. the module "A(0)")
// A cpfg file writes them as C comments, "// expect: ..." and "// also: ...": there '#'
// starts a preprocessor directive.
// Cases too big to check in (10 MB lines, nesting a million deep) are generated here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tests/support/process.h"

namespace {

namespace fs = std::filesystem;

const fs::path kCorpusDir = fs::path(SYLVA_SOURCE_DIR) / "tests" / "grammars" / "malformed";

// What a grammar file's "# expect:" header promises.
struct Expectation {
  int line = 0;
  int column = 0;
  std::vector<std::string> keywords;  // alternatives; one must occur in the message
  std::vector<std::string> also;      // each must occur in the diagnostic
};

std::string lower(std::string_view text) {
  std::string result(text);
  for (char& c : result) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return result;
}

std::vector<std::string_view> split_lines(std::string_view text, size_t max_lines) {
  std::vector<std::string_view> lines;
  while (!text.empty() && lines.size() < max_lines) {
    size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
  return lines;
}

// Parses "# expect: L:C kw|kw" and following "# also: text" lines. nullopt if malformed.
std::optional<Expectation> parse_expectation(std::string_view content) {
  std::vector<std::string_view> lines = split_lines(content, 8);
  const bool cpfg = !lines.empty() && lines[0].substr(0, 3) == "// ";
  const std::string_view kExpect = cpfg ? "// expect: " : "# expect: ", kAlso = cpfg ? "// also: " : "# also: ";
  if (lines.empty() || lines[0].substr(0, kExpect.size()) != kExpect) return std::nullopt;
  std::string_view rest = lines[0].substr(kExpect.size());
  Expectation e;
  size_t colon = rest.find(':'), space = rest.find(' ');
  if (colon == std::string_view::npos || space == std::string_view::npos || colon > space)
    return std::nullopt;
  try {
    e.line = std::stoi(std::string(rest.substr(0, colon)));
    e.column = std::stoi(std::string(rest.substr(colon + 1, space - colon - 1)));
  } catch (const std::exception&) {
    return std::nullopt;
  }
  std::string_view keywords = rest.substr(space + 1);
  while (!keywords.empty()) {
    size_t bar = keywords.find('|');
    e.keywords.emplace_back(keywords.substr(0, bar));
    if (bar == std::string_view::npos) break;
    keywords.remove_prefix(bar + 1);
  }
  for (size_t i = 1; i < lines.size() && lines[i].substr(0, kAlso.size()) == kAlso; ++i)
    e.also.emplace_back(lines[i].substr(kAlso.size()));
  if (e.line < 1 || e.column < 1 || e.keywords.empty()) return std::nullopt;
  return e;
}

// The physical line `line` (1-based) of `content`, without its line ending; empty when
// the file has fewer lines.
std::string source_line(std::string_view content, int line) {
  for (int i = 1; i < line; ++i) {
    size_t end = content.find('\n');
    if (end == std::string_view::npos) return {};
    content.remove_prefix(end + 1);
  }
  std::string_view result = content.substr(0, content.find('\n'));
  if (!result.empty() && result.back() == '\r') result.remove_suffix(1);
  return std::string(result);
}

// True for printable ASCII and tabs only: such a line must be echoed byte for byte.
bool plain_text(std::string_view line) {
  return std::all_of(line.begin(), line.end(),
                     [](char c) { return c == '\t' || (c >= 0x20 && c < 0x7f); });
}

// "FILE:LINE:COLUMN: error: MESSAGE" split into its parts. Parsed by hand: the line can
// be megabytes long, which std::regex would recurse over.
struct ReportedError {
  int line = 0;
  int column = 0;
  std::string message;
};

std::optional<ReportedError> parse_error_header(std::string_view header, std::string_view file) {
  if (header.substr(0, file.size()) != file || header.substr(file.size(), 1) != ":")
    return std::nullopt;
  header.remove_prefix(file.size() + 1);
  auto number = [&](int& value) {
    size_t digits = 0;
    while (digits < header.size() && digits < 9 && std::isdigit(static_cast<unsigned char>(header[digits])))
      ++digits;
    if (digits == 0) return false;
    value = std::stoi(std::string(header.substr(0, digits)));
    header.remove_prefix(digits);
    return true;
  };
  ReportedError reported;
  if (!number(reported.line) || header.substr(0, 1) != ":") return std::nullopt;
  header.remove_prefix(1);
  if (!number(reported.column)) return std::nullopt;
  constexpr std::string_view kError = ": error: ";
  if (header.substr(0, kError.size()) != kError) return std::nullopt;
  header.remove_prefix(kError.size());
  if (header.empty()) return std::nullopt;
  reported.message = std::string(header);
  return reported;
}

// How strictly to check the two lines after the header.
enum class Echo {
  kExact,      // the source line byte for byte, caret exactly under the column
  kCaretOnly,  // some source line (binary bytes may be escaped or lines clipped), a caret line
};

// Checks every rule for a reported grammar error. `file_arg` is the path as passed on
// the command line; `content` the file's bytes (to find the echoed source line).
// `expected.line/column` of 0 mean "any".
void expect_located_error(const ProcessResult& r, const std::string& file_arg, std::string_view content,
                          const Expectation& expected, Echo echo) {
  ASSERT_FALSE(crashed(r)) << describe(r);
  EXPECT_EQ(r.exit_code, 1) << "a malformed grammar must exit with status 1\n" << describe(r);
  EXPECT_EQ(r.out, "") << "nothing may be printed to stdout when derivation fails\n" << describe(r);

  std::vector<std::string_view> lines = split_lines(r.err, 3);
  ASSERT_FALSE(lines.empty()) << "no diagnostic on stderr\n" << describe(r);
  std::optional<ReportedError> reported = parse_error_header(lines[0], file_arg);
  ASSERT_TRUE(reported.has_value())
      << "first stderr line must read '" << file_arg << ":LINE:COLUMN: error: MESSAGE'\n" << describe(r);

  if (expected.line != 0) {
    EXPECT_EQ(reported->line, expected.line) << describe(r);
  }
  if (expected.column != 0) {
    EXPECT_EQ(reported->column, expected.column) << describe(r);
  }
  std::string message = lower(reported->message);
  bool keyword_found = std::any_of(expected.keywords.begin(), expected.keywords.end(),
                                   [&](const std::string& k) { return message.find(lower(k)) != std::string::npos; });
  std::string wanted;
  for (const std::string& k : expected.keywords) wanted += (wanted.empty() ? "'" : " or '") + k + "'";
  EXPECT_TRUE(keyword_found) << "the message should contain " << wanted << "\n" << describe(r);

  // Context the message must name (the module of a derivation error). Searched in the
  // whole diagnostic without the header's own place, so "3:1" is not found in "3:12".
  std::string diagnostic = reported->message + "\n" + r.err.substr(std::min(r.err.size(), lines[0].size()));
  for (const std::string& text : expected.also) {
    EXPECT_NE(diagnostic.find(text), std::string::npos)
        << "the diagnostic should name '" << text << "'\n" << describe(r);
  }

  ASSERT_GE(lines.size(), 3u) << "the header must be followed by the source line and a caret line\n"
                              << describe(r);
  const std::string_view echoed = lines[1], caret = lines[2];
  std::string source = source_line(content, reported->line);
  if (echo == Echo::kExact && plain_text(source)) {
    EXPECT_EQ(echoed, source) << "second stderr line must be source line " << reported->line << "\n"
                              << describe(r);
    // The column counts bytes; the caret stands under that byte's character: one blank per
    // character before it (UTF-8 continuation bytes are not characters).
    const size_t byte_column = static_cast<size_t>(reported->column);
    size_t column = 1;
    for (size_t i = 0; i + 1 < byte_column && i < source.size(); ++i)
      column += (static_cast<unsigned char>(source[i]) >> 6) != 0x2;
    bool caret_ok = caret.size() >= column && caret[column - 1] == '^' &&
                    std::all_of(caret.begin(), caret.begin() + static_cast<std::ptrdiff_t>(column - 1),
                                [](char c) { return c == ' ' || c == '\t'; });
    EXPECT_TRUE(caret_ok) << "third stderr line must put '^' under byte column " << byte_column << " (character "
                          << column << ") after blanks, got '" << caret << "'\n" << describe(r);
  } else {
    size_t hat = caret.find('^');
    bool caret_ok = hat != std::string_view::npos &&
                    std::all_of(caret.begin(), caret.begin() + static_cast<std::ptrdiff_t>(hat),
                                [](char c) { return c == ' ' || c == '\t'; });
    EXPECT_TRUE(caret_ok) << "third stderr line must be a caret line, got '"
                          << caret.substr(0, 200) << "'\n" << describe(r);
  }
}

// ---------------------------------------------------------------------------------------
// The checked-in corpus, one test per file.

struct CorpusCase {
  std::string file_name;  // "07_unknown_function.lsys"
  std::string test_name;  // "07_unknown_function"
};

void PrintTo(const CorpusCase& c, std::ostream* os) { *os << "tests/grammars/malformed/" << c.file_name; }

std::vector<CorpusCase> corpus_cases() {
  std::vector<CorpusCase> cases;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(kCorpusDir, error)) {
    if (!entry.is_regular_file() || (entry.path().extension() != ".lsys" && entry.path().extension() != ".l")) continue;
    CorpusCase c{entry.path().filename().string(), entry.path().stem().string()};
    for (char& ch : c.test_name)
      if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    cases.push_back(c);
  }
  std::sort(cases.begin(), cases.end(),
            [](const CorpusCase& a, const CorpusCase& b) { return a.file_name < b.file_name; });
  return cases;
}

class MalformedGrammarTest : public ::testing::TestWithParam<CorpusCase> {};

TEST_P(MalformedGrammarTest, DeriveReportsTheMistakeAtItsPlaceAndExitsOne) {
  const std::string relative = "tests/grammars/malformed/" + GetParam().file_name;
  const std::string content = read_file(kCorpusDir / GetParam().file_name);
  std::optional<Expectation> expected = parse_expectation(content);
  ASSERT_TRUE(expected.has_value()) << relative << ": first line must be '# expect: LINE:COLUMN KEYWORD'";

  ProcessResult r = run_sylva({"derive", relative}, SYLVA_SOURCE_DIR);
  expect_located_error(r, relative, content, *expected, Echo::kExact);
}

INSTANTIATE_TEST_SUITE_P(Corpus, MalformedGrammarTest, ::testing::ValuesIn(corpus_cases()),
                         [](const ::testing::TestParamInfo<CorpusCase>& info) { return info.param.test_name; });

TEST(MalformedCorpus, HoldsAtLeast45SmallCasesEachWithAnExpectation) {
  std::vector<CorpusCase> cases = corpus_cases();
  EXPECT_GE(cases.size(), 45u) << "corpus folder: " << kCorpusDir;
  for (const CorpusCase& c : cases) {
    const std::string content = read_file(kCorpusDir / c.file_name);
    EXPECT_TRUE(parse_expectation(content).has_value()) << c.file_name << ": bad '# expect:' line";
    EXPECT_LT(content.size(), 4096u) << c.file_name << ": corpus cases should be small";
    bool numbered = c.file_name.size() > 3 && std::isdigit(static_cast<unsigned char>(c.file_name[0])) &&
                    std::isdigit(static_cast<unsigned char>(c.file_name[1])) && c.file_name[2] == '_';
    EXPECT_TRUE(numbered) << c.file_name << ": name must be NN_short_name.lsys (or .l)";
  }
}

// ---------------------------------------------------------------------------------------
// Generated cases: written to a temporary folder, run with that folder as working
// directory so FILE in the diagnostic is the bare file name.

// Megabyte inputs: a build without optimisation and with sanitizers runs up to 100 times
// slower than a release build (10 MB derive: 1.8 s release, ~160 s Debug+ASan), so there
// they get more time before counting as a hang (ctest allows 300 s per test).
#if defined(__SANITIZE_ADDRESS__) || !defined(__OPTIMIZE__)
constexpr int kBigInputTimeout_s = 240;
#else
constexpr int kBigInputTimeout_s = 60;
#endif

class GeneratedGrammarTest : public ::testing::Test {
 protected:
  // Writes `content` to `name` in the temporary folder and runs `sylva <args> name
  // <trailing>` there.
  ProcessResult run(const std::string& name, const std::string& content, std::vector<std::string> args,
                    std::vector<std::string> trailing = {}) {
    dir_.write(name, content);
    args.push_back(name);
    args.insert(args.end(), trailing.begin(), trailing.end());
    return run_sylva(args, dir_.path().string(), kBigInputTimeout_s);
  }
  TempDir dir_;
};

TEST_F(GeneratedGrammarTest, EmptyFileHasNoAxiomReportedAtLineOneColumnOne) {
  ProcessResult r = run("empty.lsys", "", {"derive"});
  expect_located_error(r, "empty.lsys", "", Expectation{1, 1, {"no axiom"}, {}}, Echo::kExact);
}

TEST_F(GeneratedGrammarTest, TenMegabyteAxiomLineIsValidAndPrintedBack) {
  std::string word;
  word.reserve(10'000'000);
  for (int i = 0; i < 5'000'000; ++i) word += "F+";
  ProcessResult r = run("long.lsys", "axiom: " + word + "\n", {"derive"});
  ASSERT_FALSE(crashed(r)) << describe(r, 500);
  ASSERT_EQ(r.exit_code, 0) << describe(r, 500);
  EXPECT_EQ(r.out.size(), word.size() + 1) << "expected the 10 MB word and a newline";
  EXPECT_TRUE(r.out == word + "\n") << "the word must come back unchanged (no productions)";
}

TEST_F(GeneratedGrammarTest, TenMegabyteLineOfClosingParenthesesIsAnError) {
  const std::string content = "axiom: " + std::string(10'000'000, ')') + "\n";
  ProcessResult r = run("parens.lsys", content, {"derive"});
  expect_located_error(r, "parens.lsys", content,
                       Expectation{1, 8, {"expected", "without matching", "unbalanced"}, {}}, Echo::kCaretOnly);
}

TEST_F(GeneratedGrammarTest, ParenthesesNested100000DeepAreTooDeepNotACrash) {
  constexpr int kDepth = 100'000;
  const std::string content =
      "axiom: F(" + std::string(kDepth, '(') + "1" + std::string(kDepth, ')') + ")\n";
  ProcessResult r = run("deep.lsys", content, {"derive"});
  expect_located_error(r, "deep.lsys", content, Expectation{1, 0, {"nested too deeply"}, {}}, Echo::kCaretOnly);
  // The place must be one of the parentheses (columns 9 .. 9 + kDepth), not the line end.
  std::vector<std::string_view> lines = split_lines(r.err, 1);
  std::optional<ReportedError> reported;
  if (!lines.empty()) reported = parse_error_header(lines[0], "deep.lsys");
  if (reported) {
    EXPECT_GE(reported->column, 9);
    EXPECT_LE(reported->column, 9 + kDepth);
  }
}

TEST_F(GeneratedGrammarTest, MillionNestedBracketsWithOneUnclosedReportTheOutermost) {
  constexpr int kDepth = 1'000'000;
  const std::string content =
      "axiom: " + std::string(kDepth, '[') + "F" + std::string(kDepth - 1, ']') + "\n";
  ProcessResult r = run("unbalanced.lsys", content, {"derive"});
  // Inner brackets pair up; the one left open is the first, in column 8.
  expect_located_error(r, "unbalanced.lsys", content,
                       Expectation{1, 8, {"unbalanced", "never closed", "without matching"}, {}},
                       Echo::kCaretOnly);
}

std::string million_nested_brackets() {
  constexpr int kDepth = 1'000'000;
  return std::string(kDepth, '[') + "F" + std::string(kDepth, ']');
}

TEST_F(GeneratedGrammarTest, MillionNestedBalancedBracketsDeriveWithoutRecursion) {
  const std::string word = million_nested_brackets();
  ProcessResult r = run("nested.lsys", "axiom: " + word + "\n", {"derive"});
  ASSERT_FALSE(crashed(r)) << describe(r, 500);
  ASSERT_EQ(r.exit_code, 0) << describe(r, 500);
  EXPECT_TRUE(r.out == word + "\n") << "the word must come back unchanged";
}

TEST_F(GeneratedGrammarTest, MillionNestedBalancedBracketsGrowWithoutRecursion) {
  ProcessResult r = run("nested.lsys", "axiom: " + million_nested_brackets() + "\n", {"grow"},
                        {"-o", "nested.skel.json"});
  ASSERT_FALSE(crashed(r)) << describe(r, 500);
  ASSERT_EQ(r.exit_code, 0) << describe(r, 500);
  EXPECT_NE(r.out.find("2000001 modules"), std::string::npos) << describe(r, 500);
  ASSERT_TRUE(fs::exists(dir_.path() / "nested.skel.json"));
  EXPECT_NE(read_file(dir_.path() / "nested.skel.json").find("sylva-skeleton"), std::string::npos);
}

}  // namespace
