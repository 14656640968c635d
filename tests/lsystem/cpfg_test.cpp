// cpfg model files (docs/spec/grammar.md "cpfg model files and vlab objects", docs/cpfg.md):
// recognising one, the C preprocessor (macros, conditionals, includes and their errors),
// the model's own lines, and the CPFG manual's chapter 5 functions. Expected words are
// derived by hand in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "lsystem/vlab_object.h"
#include "tests/lsystem/lsystem_test_util.h"

namespace sylva::lsys {
namespace {

namespace fs = std::filesystem;
using testing::derive_text;
using testing::parse_error;
using testing::parse_ok;

// A fresh folder for files that #include each other; removed at the end of the test.
class ModelFolder {
 public:
  explicit ModelFolder(const std::string& suffix = "") {
    dir_ = fs::temp_directory_path() / ("sylva_cpfg_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                        "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + suffix);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~ModelFolder() { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
};

std::string derive_file(const std::string& path, const ParseOptions& options = {}) {
  auto g = load_grammar(path, options);
  if (!g.ok()) return "<parse error: " + g.error().format() + ">";
  auto w = derive(*g);
  if (!w.ok()) return "<error: " + g->error_at(w.error().loc, w.error().message).format() + ">";
  return print_word(*w, g->symbols);
}

// A text that must fail to parse, where and with what.
struct LocatedError {
  const char* text;
  uint32_t line, column;
  const char* says;
};

void expect_located(const LocatedError& c) {
  Diagnostic d = parse_error(c.text);
  EXPECT_EQ(d.loc.line, c.line) << c.text << "\n" << d.format();
  EXPECT_EQ(d.loc.column, c.column) << c.text << "\n" << d.format();
  EXPECT_NE(d.message.find(c.says), std::string::npos) << c.text << "\n" << d.format();
}

// ---- recognising a cpfg file ----

TEST(CpfgFile, IsTheFirstLineThatIsNoCommentOrDirectiveSayingLsystemInAnyCase) {
  EXPECT_TRUE(is_cpfg_text("Lsystem: 1\naxiom: F\nendlsystem\n"));
  EXPECT_TRUE(is_cpfg_text("/* a model\n   of a plant */\n#define N 3\n\n  lsystem : tree\n"));
  EXPECT_TRUE(is_cpfg_text("// cpp comment\nLSYSTEM:1\n"));
  EXPECT_TRUE(is_cpfg_text("\xEF\xBB\xBFLsystem: 1\n"));
  EXPECT_FALSE(is_cpfg_text("axiom: F\nLsystem: 1\n"));  // not the first line
  EXPECT_FALSE(is_cpfg_text("# a sylva comment\naxiom: F\n"));
  EXPECT_FALSE(is_cpfg_text("Lsystems: 1\n"));
  EXPECT_FALSE(is_cpfg_text("Lsystem 1\n"));
  EXPECT_FALSE(is_cpfg_text(""));
  EXPECT_TRUE(parse_ok("Lsystem: 1\nAxiom: F\nendlsystem\n").cpfg);
  EXPECT_FALSE(parse_ok("axiom: F\n").cpfg);
}

TEST(CpfgFile, SlashSlashIsACommentInACpfgFileAndTwoRollsInSylvasOwn) {
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: F//F\nendlsystem\n"), "F");
  EXPECT_EQ(derive_text("axiom: F//F\n"), "F//F");
  // Inside a string (cpfg's printf arguments) '//' is no comment; nothing else changes.
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: F /* block\n comment */ F\nendlsystem\n"), "FF");
}

// ---- the preprocessor ----

TEST(CpfgPreprocessor, ObjectAndFunctionLikeMacrosExpandAsCppDoes) {
  // BR(25) -> [+(25)F][-(25)F]; STEP -> 2 inside it through ARM; a macro is not expanded in
  // its own expansion (SELF stays SELF).
  const std::string model =
      "#define STEP 2\n#define ARM(a) +(a)F(STEP)\n#define BR(a) [ARM(a)][ARM(-a)]\n#define SELF SELF G\n"
      "Lsystem: 1\nderivation length: 1\nAxiom: A\nA --> F BR(25) SELF\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "F[+(25)F(2)][+(-25)F(2)]SELFG");
}

TEST(CpfgPreprocessor, ConditionalsChooseLinesAndSkipTheRest) {
  const std::string model =
      "#define BUSHY 1\n#define LEVEL 3\n"
      "#if BUSHY && LEVEL > 2\n#define SHAPE FF\n#elif LEVEL == 2\n#define SHAPE F\n#else\n#define SHAPE G\n#endif\n"
      "#ifdef NOT_DEFINED\n#error this branch is skipped\n#endif\n"
      "#ifndef NOT_DEFINED\n#define TAIL X\n#endif\n"
      "#if defined(TAIL) && !defined NOT_DEFINED\n#define HEAD Y\n#endif\n"
      "#undef BUSHY\n#ifdef BUSHY\n#define HEAD Z\n#endif\n"
      "Lsystem: 1\nAxiom: HEAD SHAPE TAIL\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "YFFX");
  EXPECT_NE(parse_error("#if 1\n#error stop here\n#endif\nLsystem: 1\nAxiom: F\nendlsystem\n").message.find("stop here"),
            std::string::npos);
}

TEST(CpfgPreprocessor, ANumberDefineIsADefineThatMinusDReplaces) {
  const std::string model = "#define N 2\n#define ANGLE 30\n#define SHAPE F\nLsystem: 1\nderivation length: N\n"
                            "Axiom: A\nA --> +(ANGLE)A\nendlsystem\n";
  Grammar g = parse_ok(model);
  ASSERT_EQ(g.defines.size(), 2u);  // SHAPE is text, not a number
  EXPECT_EQ(g.defines[0].name, "N");
  EXPECT_EQ(g.defines[1].value, 30);
  EXPECT_EQ(derive_text(model), "+(30)+(30)A");
  ParseOptions options;
  options.define_overrides["N"] = 1;
  options.define_overrides["ANGLE"] = -12.5;
  Grammar over = parse_ok(model, options);
  EXPECT_TRUE(over.defines[0].overridden);
  EXPECT_EQ(over.steps, 1);
  auto w = derive(over);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(print_word(*w, over.symbols), "+(-12.5)A");
  ParseOptions text_define;
  text_define.define_overrides["SHAPE"] = 1;
  EXPECT_NE(parse_error(model, text_define).message.find("no '#define SHAPE <number>'"), std::string::npos);
}

TEST(CpfgPreprocessor, MalformedDirectivesAreLocatedErrors) {
  const LocatedError cases[] = {
      {"#if 1\nLsystem: 1\nAxiom: F\nendlsystem\n", 1, 2, "no '#endif'"},
      {"#endif\nLsystem: 1\n", 1, 2, "without '#if'"},
      {"#else\nLsystem: 1\n", 1, 2, "without '#if'"},
      {"#if 1\n#else\n#else\n#endif\nLsystem: 1\n", 3, 2, "after '#else'"},
      {"#frobnicate\nLsystem: 1\n", 1, 2, "unknown preprocessor directive '#frobnicate'"},
      {"#define\nLsystem: 1\n", 1, 2, "needs a name"},
      {"#define F(a b) a\nLsystem: 1\n", 1, 13, "expected ',' or ')'"},
      {"#define A 1\n#define A 2\nLsystem: 1\n", 2, 9, "defined twice"},
      {"#define M(a) a\nLsystem: 1\nAxiom: M(1, 2)\nendlsystem\n", 3, 8, "takes 1 arguments, got 2"},
      {"#define M(a) a\nLsystem: 1\nAxiom: M(F\nendlsystem\n", 3, 8, "not closed"},
      {"#if 1 +\n#endif\nLsystem: 1\n", 1, 2, "ends too early"},
      {"#if 1 / 0\n#endif\nLsystem: 1\n", 1, 2, "division by zero"},
      {"Lsystem: 1\nAxiom: F\n/* never closed\nendlsystem\n", 3, 1, "unterminated comment"},
  };
  for (const LocatedError& c : cases) expect_located(c);
}

TEST(CpfgPreprocessor, RunawayMacrosStopWithAnErrorInBoundedTime) {
  // Each level doubles: 2^40 bytes if nothing stopped it.
  std::string model = "#define M0 FF\n";
  for (int k = 1; k <= 40; ++k)
    model += "#define M" + std::to_string(k) + " M" + std::to_string(k - 1) + " M" + std::to_string(k - 1) + "\n";
  model += "Lsystem: 1\nAxiom: M40\nendlsystem\n";
  Diagnostic d = parse_error(model);
  EXPECT_NE(d.message.find("macro expansion too large"), std::string::npos) << d.format();
  EXPECT_EQ(d.loc.line, 43u);
}

TEST(CpfgPreprocessor, IncludeReadsAFileOfTheModelsFolderAndErrorsThereShowTheChain) {
  ModelFolder folder;
  folder.write("params.h", "#define LEN 2\n#include \"sub/more.h\"\n");
  folder.write("sub/more.h", "#define KNOT K\n");
  const std::string model = folder.write("plant.l", "#include \"params.h\"\nLsystem: 1\nAxiom: F(LEN) KNOT\nendlsystem\n");
  EXPECT_EQ(derive_file(model), "F(2)K");

  // An error in an included file: at its place there, then a note at each #include.
  folder.write("bad.h", "#define OK 1\n#if OK +\n#endif\n");
  folder.write("middle.h", "\n#include \"bad.h\"\n");
  const std::string bad = folder.write("bad.l", "#include \"middle.h\"\nLsystem: 1\nAxiom: F\nendlsystem\n");
  auto g = load_grammar(bad);
  ASSERT_FALSE(g.ok());
  const Diagnostic& d = g.error();
  EXPECT_EQ(d.file, (folder.dir() / "bad.h").string());
  EXPECT_EQ(d.loc.line, 2u);
  ASSERT_EQ(d.notes.size(), 2u) << d.format();
  EXPECT_EQ(d.notes[0].file, (folder.dir() / "middle.h").string());
  EXPECT_EQ(d.notes[0].loc.line, 2u);
  EXPECT_EQ(d.notes[1].file, bad);
  EXPECT_EQ(d.notes[1].loc.line, 1u);
  EXPECT_NE(d.format().find("included from here"), std::string::npos);
  EXPECT_EQ(*d.source_line, "#if OK +");

  // A derivation error in a production that an included file holds points into it.
  folder.write("rules.h", "A --> F(1/0)\n");
  const std::string rules = folder.write("rules.l", "Lsystem: 1\nAxiom: A\n#include \"rules.h\"\nendlsystem\n");
  const std::string message = derive_file(rules);
  EXPECT_NE(message.find((folder.dir() / "rules.h").string() + ":1:10: error: division by zero"), std::string::npos)
      << message;
  EXPECT_NE(message.find(rules + ":3:10: note: included from here"), std::string::npos) << message;
}

TEST(CpfgPreprocessor, IncludeStaysInsideTheModelsFolderAndNeverRecurses) {
  ModelFolder folder;
  folder.write("loop_a.h", "#include \"loop_b.h\"\n");
  folder.write("loop_b.h", "#include \"loop_a.h\"\n");
  folder.write("outside.h", "#define X 1\n");
  struct Case {
    const char* line;
    const char* says;
  };
  const Case cases[] = {
      {"#include \"loop_a.h\"", "includes itself"},
      {"#include \"self.l\"", "includes itself"},
      {"#include \"../outside.h\"", "only a file in the model's folder"},
      {"#include \"/etc/hostname\"", "only a file in the model's folder"},
      {"#include \"missing.h\"", "missing.h"},
      {"#include missing.h", "in quotes"},
  };
  for (const Case& c : cases) {
    const std::string model = folder.write("self.l", std::string(c.line) + "\nLsystem: 1\nAxiom: F\nendlsystem\n");
    auto g = load_grammar(model);
    ASSERT_FALSE(g.ok()) << c.line;
    EXPECT_NE(g.error().message.find(c.says), std::string::npos) << c.line << "\n" << g.error().format();
  }
  // A link that leads out of the folder is refused too.
  ModelFolder other("_other");
  const std::string target = other.write("secret.h", "#define S 1\n");
  fs::create_symlink(target, folder.dir() / "link.h");
  const std::string linked = folder.write("linked.l", "#include \"link.h\"\nLsystem: 1\nAxiom: F\nendlsystem\n");
  auto g = load_grammar(linked);
  ASSERT_FALSE(g.ok());
  EXPECT_NE(g.error().message.find("outside the model's folder"), std::string::npos) << g.error().format();
}

// ---- the model ----

TEST(CpfgModel, HeaderWordsInAnyCaseAnEmptySuccessorAndEndlsystem) {
  // A -> B*: A(1) grows to B with the '*' production deleting C.
  EXPECT_EQ(derive_text("lsystem: plant\nDerivation Length: 2\nAXIOM: A C\nA --> B A\nC --> *\nendlsystem\n"), "BBA");
  Diagnostic missing_end = parse_error("Lsystem: 1\nAxiom: F\nF --> FF\n");
  EXPECT_NE(missing_end.message.find("no 'endlsystem'"), std::string::npos);
  Diagnostic after = parse_error("Lsystem: 1\nAxiom: F\nendlsystem\nF --> FF\n");
  EXPECT_EQ(after.loc.line, 4u);
  EXPECT_NE(after.message.find("after 'endlsystem'"), std::string::npos);
  EXPECT_NE(parse_error("Lsystem: 1\nAxiom: F\nF -->\nendlsystem\n").message.find("'*' for none"), std::string::npos);
  // '*' is a module of sylva's own format, never an empty successor there.
  EXPECT_EQ(derive_text("axiom: A\nA -> *\n"), "*");
}

TEST(CpfgModel, ConsiderMakesContextSeeOnlyTheNamedModules) {
  // consider: A B — the + between them is not seen, so A > B matches.
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: A+B\nconsider: A B\nA > B --> X\nendlsystem\n"), "X+B");
  // Without it the + is seen and the production does not apply.
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: A+B\nA > B --> X\nendlsystem\n"), "A+B");
  EXPECT_NE(parse_error("Lsystem: 1\nAxiom: F\nignore: +\nconsider: F\nendlsystem\n").message.find("cannot both"),
            std::string::npos);
}

// The word the turtle reads: `g` derived and interpreted, printed (or the error).
std::string drawn_text(const Grammar& g) {
  auto w = derive(g);
  if (!w.ok()) return "<error: " + w.error().message + ">";
  auto drawn = interpret(g, *w);
  if (!drawn.ok()) return "<error: " + drawn.error().message + ">";
  return print_word(*drawn, g.symbols);
}

TEST(CpfgModel, AHomomorphismIsAppliedOnceUnlessMaximumDepthSaysMore) {
  Grammar once = parse_ok("Lsystem: 1\nAxiom: X\nhomomorphism\nX --> Y\nY --> F\nendlsystem\n");
  EXPECT_EQ(once.max_depth, 1);
  EXPECT_EQ(drawn_text(once), "Y");
  // A seed after 'homomorphism' is the homomorphism's (manual 4.3.3), never the derivation's.
  Grammar twice = parse_ok(
      "Lsystem: 1\nseed: 5\nAxiom: X\nhomomorphism: warnings\nseed: 9\nmaximum depth: 2\nX --> Y\nY --> F\nendlsystem\n");
  EXPECT_EQ(twice.seed, 5u);
  EXPECT_EQ(drawn_text(twice), "F");
}

TEST(CpfgModel, TheChapterSixModuleNamesAreOneModuleEach) {
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: @Gs@o(2)?P(0,0)@v;(3),#!\nendlsystem\n"), "@Gs@o(2)?P(0,0)@v;(3),#!");
  Grammar g = parse_ok("Lsystem: 1\nAxiom: @Gs\nendlsystem\n");
  auto w = derive(g);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(w->size(), 1u);
}

// cpfg's reader takes a newline followed by a tab as a space (cpfg/lsys_input.l): vlab's
// models write long successors, and a production's condition and its arrow, over lines that
// begin with a tab. After a blank line a tab-led line is a line of its own.
TEST(CpfgModel, ALineBeginningWithATabGoesOnTheLineBefore) {
  // A(1): the condition on the first line, the arrow and successor on tab lines; B: a
  // precondition block, then the arrow on the next line. The axiom goes on too.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: A(1)\n\tB\n"
                        "A(x) : x > 0 -->\n\tF(x)\n\t[+F]\n\tA(x - 1)\n"
                        "B : {y = 2;}\n\t--> C(y)\nendlsystem\n"),
            "F(1)[+F]A(0)C(2)");
  // `#(0.06)` leading a tab line is the line-width module, not a directive; cpfg skips the
  // blanks between a module and its arguments.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: A\nA --> F\t// a comment\n\t#(0.06) \\ (90) f(1)\n"
                        "endlsystem\n"),
            "F#(0.06)\\(90)f(1)");
  // After a blank line, a tab-led production is one of its own.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: A B\nA --> C\n\n\tB --> D\nendlsystem\n"), "CD");
  // sylva's own format is unchanged: a tab-led line there is a line.
  EXPECT_EQ(derive_text("axiom: A B\nA -> C\n\tB -> D\nsteps: 1\n"), "CD");
}

// A preprocessor line that a trailing backslash carries on (vlab's models write it doubled,
// `\\`, which cpfg's reader skips) is one directive: the model is still a cpfg file.
TEST(CpfgPreprocessor, ABackslashCarriesADirectiveOnToTheNextLine) {
  const char* model = "#define twice(x) \\\\\n\t(2 * x)\n#define sum(a, b) (a + \\\n b)\n"
                      "Lsystem: 1\nderivation length: 1\nAxiom: A(3)\nA(y) --> B(twice(y), sum(y, 1))\nendlsystem\n";
  EXPECT_TRUE(is_cpfg_text(model));
  EXPECT_EQ(derive_text(model), "B(6,4)");
}

// C's conditional `c ? a : b` in a cpfg file's expressions and statements (cpfg's reader has
// `?` and `:`), right associative; only the branch chosen is evaluated.
TEST(CpfgStatements, TheConditionalOperatorChoosesOneBranch) {
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: A(1) A(-1) A(5)\n"
                        "A(x) : * {c = x > 0 ? 3 : 4;} --> B(c, x < 0 ? -1 : x > 2 ? 2 : 1, x > -2 ? 1 : 1 / (x + 1))\n"
                        "endlsystem\n"),
            "B(3,1,1)B(4,-1,1)B(3,2,1)");
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: F(1 ? 2 : 1 / 0)\nendlsystem\n"), "F(2)");
  expect_located({"Lsystem: 1\nAxiom: F(1 ? 2)\nendlsystem\n", 2, 15, "expected ':' in the conditional"});
  EXPECT_FALSE(parse_error("axiom: F(1 ? 2 : 3)\n").message.empty()) << "not in sylva's own format";
}

// cpfg's strict predecessor may be several modules (its PredDiff): they match consecutive
// modules of the word, no module passed over, with their parameter counts, and are rewritten
// together; the right context starts after the last of them.
TEST(CpfgModel, APredecessorOfSeveralModulesRewritesConsecutiveModulesTogether) {
  // X F(3): A(3). X G: no match, X and G copied. F(2) F(1): 2 > 1, B(1). The last X alone.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: X F(3) X G F(2) F(1) X\n"
                        "XF(x) --> A(x)\nF(a) F(b) : a > b --> B(a - b)\nendlsystem\n"),
            "A(3)XGB(1)X");
  // Contexts around the pair: Q < Y Z > W.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: Q Y Z W Y Z V\nQ < Y Z > W --> U\nY Z > V --> T\n"
                        "endlsystem\n"),
            "QUWTV");
  expect_located({"axiom: A B\nA B -> C\n", 2, 1, "the predecessor must be one module"});
}

// Sub-L-systems (CPFG manual 7.2; cpfg's CheckPred): reading the word, ?(label, s) makes
// L-system `label` the one whose productions (and homomorphism) apply, up to its $. A
// sub-L-system's axiom and derivation length are not used.
TEST(CpfgModel, SubLSystemsRewriteTheModulesBetweenTheirCallAndItsEnd) {
  const std::string text =
      "Lsystem: 1\nderivation length: 2\nAxiom: A\nA --> F?(2,0.5)B(1)$A\nB(x) --> X\nhomomorphism\nA --> K\n"
      "endlsystem\nLsystem: 2\nderivation length: 9\nAxiom: B(5)\nB(x) --> F(x)B(x+1)\nhomomorphism\nB(x) --> G(x)\n"
      "endlsystem\n";
  // Step 1: A. Step 2: B(1) inside ?(2, ...) ... $ by L-system 2's production, not the main's.
  EXPECT_EQ(derive_text(text), "F?(2,0.5)F(1)B(2)$F?(2,0.5)B(1)$A");
  auto g = parse_grammar(text, "s.l");
  ASSERT_TRUE(g.ok()) << g.error().format();
  EXPECT_EQ(drawn_text(*g), "F?(2,0.5)F(1)G(2)$F?(2,0.5)G(1)$K");
  // Nested calls return to the caller's L-system; a stray $ at the top leaves the main one.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: $B?(2)B?(1)B$B$B\nB --> M\nendlsystem\n"
                        "Lsystem: 2\nAxiom: B\nB --> S\nendlsystem\n"),
            "$M?(2)S?(1)M$S$M");
  // A sub-L-system's blocks run after the main one's, over the same globals (cpfg's
  // Evaluate*Statements): Start n = 1 then 11; each step's EndEach doubles, then adds 1.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 2\nStart: {n = 1;}\nEndEach: {n = n * 2;}\nAxiom: A\n"
                        "A --> A B(n)\nendlsystem\nLsystem: 2\nStart: {n = n + 10;}\nEndEach: {n = n + 1;}\nAxiom: B\n"
                        "endlsystem\n"),
            "AB(23)B(11)");
  expect_located({"Lsystem: 1\nAxiom: A\nendlsystem\nLsystem: 2\nStart: {n = 1;}\nStart: {n = 2;}\nAxiom: B\n"
                  "endlsystem\n", 6, 1, "given twice"});
  // A cut inside a sub-L-system ends at its $ (cpfg's SkipCutPart).
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: ?(2)A%B[C]$D\nendlsystem\nLsystem: 2\nAxiom: B\n"
                        "endlsystem\n"),
            "?(2)A$D");
  // What the file does not define, and what a sub-L-system may not hold yet.
  auto unknown = derive_text("Lsystem: 1\nAxiom: ?(7,1)B$\nendlsystem\nLsystem: 2\nAxiom: B\nendlsystem\n",
                             [] { DeriveOptions o; o.steps = 1; return o; }());
  EXPECT_NE(unknown.find("?(7, ...) calls an L-system the file does not define (its labels: 1, 2)"), std::string::npos)
      << unknown;
  expect_located({"Lsystem: 1\nAxiom: A\nendlsystem\nLsystem: 1\nAxiom: B\nendlsystem\n", 4, 10,
                  "a second L-system with the label 1"});
  expect_located({"Lsystem: 1\nAxiom: A\nendlsystem\nF --> G\n", 4, 1, "expected a sub-L-system's 'Lsystem:' line"});
  expect_located({"Lsystem: 1\nAxiom: A\nLsystem: 2\nendlsystem\n", 3, 1, "'endlsystem' first"});
}

// Each L-system of a cpfg file has its own ignore or consider list, ring and maximum depths
// (cpfg keeps them per LSYSDATA; its RconDiff/LconDiff read the current L-system's): a
// sub-L-system without a list passes over nothing, whatever the main one ignores.
TEST(CpfgModel, EachSubLSystemHasItsOwnContextListRingAndMaximumDepths) {
  const std::string two = "Lsystem: 1\nderivation length: 1\n%sAxiom: %s\n%s\nendlsystem\nLsystem: 2\n%sAxiom: B\n%s\n"
                          "endlsystem\n";
  auto file = [&](const std::string& main_head, const std::string& axiom, const std::string& main_rules,
                  const std::string& sub_head, const std::string& sub_rules) {
    std::string t;
    size_t k = 0;
    for (const std::string* part : {&main_head, &axiom, &main_rules, &sub_head, &sub_rules}) {
      const size_t at = two.find("%s", k);
      t += two.substr(k, at - k) + *part;
      k = at + 2;
    }
    return t + two.substr(k);
  };
  // The main L-system ignores +, the sub-L-system does not: only the main one's B sees its A.
  EXPECT_EQ(derive_text(file("ignore: +\n", "A+B?(2)A+B$", "A < B --> C", "", "A < B --> D")), "A+C?(2)A+B$");
  EXPECT_EQ(derive_text(file("", "A+B?(2)A+B$", "A < B --> C", "ignore: +\n", "A < B --> D")), "A+B?(2)A+D$");
  // consider: in the sub-L-system only (X is passed over there, not in the main one).
  EXPECT_EQ(derive_text(file("", "AXB?(2)AXB$", "A < B --> C", "consider: A B\n", "A < B --> E")), "AXB?(2)AXE$");
  // A ring sub-L-system: its B, the word's last module, has the word's first as right context.
  EXPECT_EQ(derive_text(file("", "A?(2)B", "", "ring lsystem\n", "B > A --> X")), "A?(2)X");
  EXPECT_EQ(derive_text(file("", "A?(2)B", "", "", "B > A --> X")), "A?(2)B");
  // Maximum depths: the homomorphism's (main 1, sub 3), the decomposition's (main 2, sub 1).
  const std::string chain = "X --> Y\nY --> Z\nZ --> W";
  auto g = parse_grammar(file("", "X?(2)X$", "homomorphism\nmaximum depth: 1\n" + chain, "",
                              "homomorphism\nmaximum depth: 3\n" + chain),
                         "s.l");
  ASSERT_TRUE(g.ok()) << g.error().format();
  EXPECT_EQ(drawn_text(*g), "Y?(2)W$");
  EXPECT_EQ(derive_text(file("", "X?(2)X$", "decomposition\nmaximum depth: 2\n" + chain, "",
                             "decomposition\nmaximum depth: 1\n" + chain),
                        [] { DeriveOptions o; o.steps = 0; return o; }()),
            "Z?(2)Y$");
  // With context, the decomposition goes pass by pass: pass 2 leaves the main one's Y.
  const std::string with_context = "B < X --> Y\nY --> Z";
  EXPECT_EQ(derive_text(file("", "BX?(2)BX$", "decomposition\nmaximum depth: 1\n" + with_context, "",
                             "decomposition\nmaximum depth: 2\n" + with_context),
                        [] { DeriveOptions o; o.steps = 0; return o; }()),
            "BY?(2)BZ$");
  // Each list once per L-system, as in the main one.
  const std::string both = file("", "A", "", "ignore: F\nconsider: G\n", "");
  expect_located({both.c_str(), 8, 10, "cannot both be given"});
}

// cpfg's cut (generate.c's ApplyProd): a % a production writes stays in the word, and cuts
// itself and the rest of its branch when the next step reads it; what follows it is still
// rewritten meanwhile. sylva's own format cuts as the word is written.
TEST(CpfgModel, APercentCutsTheRestOfItsBranchWhenTheNextStepReadsIt) {
  const std::string model = "Lsystem: 1\nderivation length: %d\nAxiom: A[XBD]C\nX --> %\nB --> E\nendlsystem\n";
  auto with_steps = [&](int n) {
    std::string t = model;
    t.replace(t.find("%d"), 2, std::to_string(n));
    return derive_text(t);
  };
  EXPECT_EQ(with_steps(1), "A[%ED]C");
  EXPECT_EQ(with_steps(2), "A[]C");
  EXPECT_EQ(derive_text("axiom: A[XBD]C\nX -> %\nB -> E\n"), "A[]C") << "sylva's own format";
  // vlab's canalization model: the florets of the step before are rewritten behind the %.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 3\nAxiom: M\nM --> MX[A]\nX --> %\nA --> B\nendlsystem\n"),
            "MX[A]%[B]");
  // The axiom's % waits for the first step too.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 0\nAxiom: F%F\nendlsystem\n"), "F%F");
}

// Output files (CPFG manual 5.4; vlab's canalization-file): fopen(name, "w") in the model's
// folder, fprintf appends, fflush and fclose write the whole file atomically, and a file left
// open is written when the derivation ends. Outside the folder, an unknown id and a model of
// no file are errors at their place.
TEST(CpfgStatements, FopenAndFprintfWriteFilesBesideTheModel) {
  ModelFolder folder;
  const std::string model = folder.write(
      "plant.l", "Lsystem: 1\nderivation length: 3\nStart: {n = 0; f = fopen(\"out.txt\", \"w\"); "
                 "g = fopen(\"log/open.txt\", \"w\");}\nStartEach: {n = n + 1;}\n"
                 "EndEach: {fprintf(f, \"step %.0f: %g\\n\", n, n / 2); fflush(f); fprintf(g, \"%.0f \", n);}\n"
                 "End: {fclose(f);}\nAxiom: A\nA --> AB\nendlsystem\n");
  std::filesystem::create_directories(folder.dir() / "log");
  EXPECT_EQ(derive_file(model), "ABBB");
  auto text = [&](const char* name) {
    std::ifstream in(folder.dir() / name);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(text("out.txt"), "step 1: 0.5\nstep 2: 1\nstep 3: 1.5\n");
  EXPECT_EQ(text("log/open.txt"), "1 2 3 ") << "left open: written at the derivation's end";
  folder.write("bad.l", "Lsystem: 1\nStart: {f = fopen(\"../escape.txt\", \"w\");}\nAxiom: A\nendlsystem\n");
  const std::string outside = derive_file((folder.dir() / "bad.l").string());
  EXPECT_NE(outside.find("outside the model's folder"), std::string::npos) << outside;
  EXPECT_FALSE(std::filesystem::exists(folder.dir().parent_path() / "escape.txt"));
  // A model read from no file (Python's Grammar(text), "<string>") has no folder to write in.
  auto from_text = [](const std::string& text) {
    auto g = parse_grammar(text, "<string>");
    if (!g.ok()) return "<parse error: " + g.error().message + ">";
    auto w = derive(*g);
    return w.ok() ? print_word(*w, g->symbols) : "<error: " + w.error().message + ">";
  };
  const std::string unknown = from_text("Lsystem: 1\nStart: {fprintf(3, \"x\");}\nAxiom: A\nendlsystem\n");
  EXPECT_NE(unknown.find("3 is no open file"), std::string::npos) << unknown;
  const std::string nofile = from_text("Lsystem: 1\nStart: {f = fopen(\"x.txt\", \"w\");}\nAxiom: A\nendlsystem\n");
  EXPECT_NE(nofile.find("read from no file"), std::string::npos) << nofile;
}

// Reading files (CPFG manual 5.4): fopen(name, "r") in the model's folder, and fscanf (the
// manual's fscan) reads numbers into globals, array elements, a production's parameters and
// locals, with C's result: how many were read, 0 at a mismatch, -1 at the file's end.
TEST(CpfgStatements, FscanfReadsNumbersFromAFileBesideTheModel) {
  ModelFolder folder;
  folder.write("data.txt", "3 0.5\nlength: 2.25\n7e-1 x");
  folder.write("one.txt", " +1\n");
  folder.write("nums.txt", "10 20\n30");
  const std::string model = folder.write(
      "plant.l",
      "Lsystem: 1\ndefine: { array a[2]; }\nderivation length: 1\n"
      "Start: {f = fopen(\"data.txt\", \"r\"); r1 = fscanf(f, \"%f %f\", &n, &w); r2 = fscanf(f, \" length: %g\", &len);\n"
      "  r3 = fscanf(f, \"%f %f\", &a[0], &a[1]); r4 = fscanf(f, \"%f\", &z); fclose(f);\n"
      "  g = fopen(\"one.txt\", \"r\"); r5 = fscanf(g, \"%lf\", &z); r6 = fscanf(g, \"%f\", &z);\n"
      "  h = fopen(\"nums.txt\", \"r\");}\n"
      "Axiom: S(n, w, len, a[0], a[1], r1, r2, r3, r4, r5, r6, z) A(0) A(0) A(0) A(0)\n"
      "A(x) : {k = fscanf(h, \"%f\", &x);} --> B(x, k)\nendlsystem\n");
  EXPECT_EQ(derive_file(model), "S(3,0.5,2.25,0.7,0,2,1,1,0,1,-1,1)B(10,1)B(20,1)B(30,1)B(0,-1)");
  // What fscanf cannot read, and targets that are no variables, are errors at their place.
  expect_located({"Lsystem: 1\nStart: {f = fopen(\"a\", \"r\"); fscanf(f, \"%d\", &x);}\nAxiom: A\nendlsystem\n", 2,
                  40, "fscanf's %d: every cpfg variable is a number"});
  expect_located({"Lsystem: 1\nStart: {fscanf(1, \"%f\", x);}\nAxiom: A\nendlsystem\n", 2, 25, "write '&'"});
  expect_located({"Lsystem: 1\nStart: {fscanf(1, \"%f %f\", &x);}\nAxiom: A\nendlsystem\n", 2, 9,
                  "reads 2 values, it was given 1 variable"});
  expect_located({"Lsystem: 1\nAxiom: A(1)\nA(x) : {fscanf(1, \"%f\", &y);} --> B\nendlsystem\n", 3, 26,
                  "'y' is no parameter, local assigned before, or global"});
  expect_located({"Lsystem: 1\nStart: {f = fopen(\"a\", \"rw\");}\nAxiom: A\nendlsystem\n", 2, 24,
                  "fopen's mode is \"w\" (writing) or \"r\" (reading)"});
  // At run time: a missing file, one outside the folder, writing to one read, reading one written.
  auto run = [&](const std::string& start) {
    return derive_file(folder.write("bad.l", "Lsystem: 1\nStart: {" + start + "}\nAxiom: A\nendlsystem\n"));
  };
  const std::string missing = run("f = fopen(\"none.txt\", \"r\");");
  EXPECT_NE(missing.find("none.txt"), std::string::npos) << missing;
  EXPECT_NE(missing.find("No such file"), std::string::npos) << missing;
  EXPECT_NE(run("f = fopen(\"../data.txt\", \"r\");").find("outside the model's folder"), std::string::npos);
  EXPECT_NE(run("f = fopen(\"one.txt\", \"r\"); fprintf(f, \"x\");").find("opened for reading"), std::string::npos);
  EXPECT_NE(run("f = fopen(\"o.txt\", \"w\"); fscanf(f, \"%f\", &x);").find("opened for writing"), std::string::npos);
  EXPECT_NE(run("f = fopen(\"one.txt\", \"r\"); fclose(f); fscanf(f, \"%f\", &x);").find("is no open file"),
            std::string::npos);
}

// stop(n) (CPFG manual 5.6) ends the derivation after the step that calls it: the word is
// that step's, and the End block still runs.
TEST(CpfgStatements, StopEndsTheDerivationAfterTheCurrentStep) {
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 10\nStart: {n=0;}\nEndEach: {n=n+1; if (n==3) {stop(1);}}\n"
                        "End: {printf(\"\");}\nAxiom: A\nA --> AB\nendlsystem\n"),
            "ABBB");
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 10\nAxiom: A(0)\nA(n) : n == 1 {stop(0);} --> A(n+1)\n"
                        "A(n) --> A(n+1)\nendlsystem\n"),
            "A(2)");
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 10\nStart: {stop(1);}\nAxiom: A\nA --> AB\nendlsystem\n"), "A");
}

// In a homomorphism or a decomposition too (generate.c's ApplyRecursiveProductions): at the
// first depth the word's consecutive modules, deeper the rest of the same successor only.
// cpfg has no labels: "AXIOM : c" is five modules and a condition (vlab's Lilac), "Sl :" two.
TEST(CpfgModel, APredecessorOfSeveralModulesWorksInAHomomorphismAndADecomposition) {
  // Homomorphism: L becomes S l T; "S l" is rewritten at depth 2, "l T" never (S l went first).
  const std::string homo = "Lsystem: 0\nderivation length: 0\nAxiom: L F L\nhomomorphism\nmaximum depth: 3\n"
                           "L --> S l T\nSl : 1 --> [G]\nl T --> X\nT --> +\nendlsystem\n";
  auto g = parse_grammar(homo, "h.l");
  ASSERT_TRUE(g.ok()) << g.error().message;
  EXPECT_EQ(drawn_text(*g), "[G]+F[G]+");
  // Depth 1 reads the word: A B together; a B that ended another successor is not taken.
  const std::string pair = "Lsystem: 0\nderivation length: 0\nAxiom: A B A C\nhomomorphism\nmaximum depth: 3\n"
                           "A B --> F\nC --> A\nA --> G\nendlsystem\n";
  auto h = parse_grammar(pair, "p.l");
  ASSERT_TRUE(h.ok()) << h.error().message;
  EXPECT_EQ(drawn_text(*h), "FGG");
  // Decomposition of the axiom, five modules with a condition; its result stays in the word.
  EXPECT_EQ(derive_text("#define SW 2\nLsystem: 1\nderivation length: 0\nAxiom: AXIOM\ndecomposition\n"
                        "maximum depth: 10\nAXIOM : SW == 1 --> F\nAXIOM : SW == 2 --> K(2)\nendlsystem\n"),
            "K(2)");
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: Q\nQ --> Q Y Z\ndecomposition\n"
                        "maximum depth: 10\nY Z --> W(1)\nendlsystem\n"),
            "QW(1)");
}

// cpfg compares parameter counts when it matches (PredDiff): a module that no production of
// its symbol takes with its count is copied; sylva's own format says so as an error.
TEST(CpfgModel, AModuleNoProductionTakesWithItsParameterCountIsCopied) {
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: G(0.25) G\nG --> I\nendlsystem\n"), "G(0.25)I");
  DeriveOptions one;
  one.steps = 1;
  auto w = derive(parse_ok("axiom: G(1)\nG -> I\n"), one);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("parameter count"), std::string::npos) << w.error().message;
}

// cpfg's printf in statements (C's, as cpfg passes it on): the format with its values,
// written where print_sink says (standard error by default); its mistakes are located.
std::string printed_text;
void capture(std::string_view text) { printed_text += text; }

TEST(CpfgStatements, PrintfWritesItsFormatWithItsValues) {
  printed_text.clear();
  const PrintSink before = set_print_sink(capture);
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 2\nStart: {printf(\"n=%d x=%5.2f %%\\n\", 3.7, 0.5);}\n"
                        "Axiom: A(1)\nA(x) : * {printf(\"[%g;%x]\", x, 255);} --> A(x + 1)\nendlsystem\n"),
            "A(3)");
  set_print_sink(before);
  EXPECT_EQ(printed_text, "n=3 x= 0.50 %\n[1;ff][2;ff]");
  expect_located({"Lsystem: 1\nStart: {printf(\"%s\", 1);}\nAxiom: F\nendlsystem\n", 2, 16, "%s"});
  expect_located({"Lsystem: 1\nStart: {printf(\"%g %g\", 1);}\nAxiom: F\nendlsystem\n", 2, 9, "takes 2 values"});
  expect_located({"Lsystem: 1\nStart: {printf(x);}\nAxiom: F\nendlsystem\n", 2, 16, "format string"});
  EXPECT_NE(parse_error("axiom: F(printf(\"%g\", 1))\n").message.find("unknown function 'printf'"), std::string::npos);
}

// What cpfg's reader takes and sylva's own format does not: `%` (C's remainder of the values
// made ints), an axiom reading the globals Start set, `a[M][N]` arrays, @L's text dropped,
// brackets in the ignore list.
TEST(CpfgModel, RemainderAxiomGlobalsArraysLabelsAndIgnoredBrackets) {
  // 7 % 3 = 1; -7.9 % 3: -7 % 3 = -1 (C truncates); 5 % 2.5: 5 % 2 = 1.
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: F(7 % 3, -7.9 % 3, 5 % 2.5)\nendlsystem\n"), "F(1,-1,1)");
  expect_located({"Lsystem: 1\nAxiom: F(7 % 0.5)\nendlsystem\n", 2, 12, "remainder by zero"});
  EXPECT_FALSE(parse_error("axiom: F(7 % 3)\n").message.empty()) << "not in sylva's own format";
  EXPECT_EQ(derive_text("Lsystem: 1\nStart: {x0 = 2; y0 = x0 * 3;}\nAxiom: A(x0, y0 + 1)\nendlsystem\n"), "A(2,7)");
  EXPECT_EQ(derive_text("#define M 2\n#define N 3\nLsystem: 1\ndefine: {\n\tarray a[M][N] = {1, 2, 3,\n\t\t4, 5, 6};\n\t}\n"
                        "derivation length: 1\nAxiom: A\nA --> B(a[1][2], a[0, 1])\nendlsystem\n"),
            "B(6,2)");
  EXPECT_EQ(derive_text("Lsystem: 1\nAxiom: F @L(\"n = %g, (%d)\", 3, 4) F\nendlsystem\n"), "F@L(3,4)F");
  // A < B ignores + and, in a cpfg file, the brackets of the list change nothing.
  EXPECT_EQ(derive_text("Lsystem: 1\nignore: [+]\nderivation length: 1\nAxiom: A + B\nA < B --> C\nendlsystem\n"), "A+C");
}

// cpfg's `=` in a right context (generate.c's skipright) stands for the rest of the branch the
// pattern is in: the pipe models of vlab's Borchert–Slade and Lilac read a lateral's first
// module whatever follows it. I(1) sees [I(2) ...] and then I(3): I(6). sylva's own format has
// no such symbol (there `=` would be a module).
TEST(CpfgModel, AnEqualsSignInARightContextIsTheRestOfTheBranch) {
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: I(1) [I(2) X Y] I(3)\n"
                        "I(a) > [I(b)=]I(c) --> I(a + b + c)\nendlsystem\n"),
            "I(6)[I(2)XY]I(3)");
  // `=` over nothing (the branch ends at once) still matches; nothing after the branch: none.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: I(1) [I(2)] I(3) [I(4) X]\n"
                        "I(a) > [I(b)=]I(c) --> I(a + b + c)\nendlsystem\n"),
            "I(6)[I(2)]I(3)[I(4)X]");
}

// ---- ring L-systems (CPFG manual 3.1.1) ----

TEST(CpfgRing, ContextWrapsFromTheLastModuleToTheFirstAndBack) {
  // The manual's example: the A of "A B C" has C as its left context in a ring.
  EXPECT_EQ(derive_text("Lsystem: 1\nring lsystem\nderivation length: 1\nAxiom: A B C\nC < A --> X\nendlsystem\n"),
            "XBC");
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: A B C\nC < A --> X\nendlsystem\n"), "ABC");
  // Right context: C's right neighbour is A; a context longer than one module wraps on.
  EXPECT_EQ(derive_text("Lsystem: 1\nring lsystem\nderivation length: 1\nAxiom: A B C\nC > A B --> Y\n"
                        "B < C > A --> Z\nendlsystem\n"),
            "ABY");
  // A signal passed around a ring of cells: each cell takes its left neighbour's value, so
  // after three steps on three cells every value is back where it started.
  const std::string cells = "Lsystem: 1\nring lsystem\nderivation length: N\nAxiom: c(1) c(2) c(3)\n"
                            "c(l) < c(x) --> c(l)\nendlsystem\n";
  auto after = [&](int n) {
    std::string m = cells;
    m.replace(m.find("N"), 1, std::to_string(n));
    return derive_text(m);
  };
  EXPECT_EQ(after(1), "c(3)c(1)c(2)");
  EXPECT_EQ(after(3), "c(1)c(2)c(3)");
  // Ignored modules are passed over across the seam too.
  EXPECT_EQ(derive_text("Lsystem: 1\nring lsystem\nignore: +\nderivation length: 1\nAxiom: A B C +\nC < A --> X\n"
                        "endlsystem\n"),
            "XBC+");
  // 'ring lsystem' comes before the axiom.
  expect_located({"Lsystem: 1\nAxiom: A\nring lsystem\nendlsystem\n", 3, 1, "before the axiom"});
}

// ---- arrays (CPFG manual 2.2.2) ----

TEST(CpfgArrays, DefineInitialiseReadAndAssignFromBlocksProductionsAndSuccessors) {
  // Len is initialised, G is 2 x 2 row-major (read as G[i, j] or G[i][j]), Count starts at
  // 0; the Start block sets Count[0]; every step's statements count in Count[1]. The define
  // block spans lines and its size is a #define.
  const std::string model =
      "#define N 3\nLsystem: 1\nderivation length: 3\n"
      "define: { array Len[N] = {1, 0.5, 0.25};\n          array G[2,2] = {1, 2,\n 3, 4};\n"
      "          array Count[2]; }\n"
      "Start: { Count[0] = 10; }\nAxiom: A(0)\n"
      "A(i) : i < N { Count[1] += 1; x = G[1,0] + G[0][1]; } --> F(Len[i]) B(x, Count[0], Count[1]) A(i+1)\n"
      "endlsystem\n";
  EXPECT_EQ(derive_text(model), "F(1)B(5,10,1)F(0.5)B(5,10,2)F(0.25)B(5,10,3)A(3)");
  Grammar g = parse_ok(model);
  ASSERT_EQ(g.program.arrays.size(), 3u);
  EXPECT_EQ(g.program.arrays[1].dims, (std::vector<uint32_t>{2, 2}));
  EXPECT_EQ(g.global_names.size(), 3u + 4u + 2u);
  // An index is truncated toward zero, as C converts it (1.9 reads element 1); compound
  // assignments read and write the same element.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\ndefine: { array a[3] = {4, 5, 6}; }\nAxiom: A\n"
                        "A : { a[2] *= 10; a[0] -= 1; } --> B(a[1.9], a[2], a[0])\nendlsystem\n"),
            "B(5,60,3)");
}

TEST(CpfgArrays, BadDefinitionsAndIndicesAreErrorsAtTheirPlace) {
  const LocatedError cases[] = {
      {"Lsystem: 1\ndefine: { array a[0]; }\nAxiom: F\nendlsystem\n", 2, 19, "an array's size must be"},
      {"Lsystem: 1\ndefine: { array a[2] = {1, 2, 3}; }\nAxiom: F\nendlsystem\n", 2, 31, "too many values"},
      {"Lsystem: 1\ndefine: { array a[2]; array a[3]; }\nAxiom: F\nendlsystem\n", 2, 29, "already defined"},
      {"Lsystem: 1\ndefine: { vector a[2]; }\nAxiom: F\nendlsystem\n", 2, 11, "expected 'array"},
      {"Lsystem: 1\ndefine: { array a[2000000]; }\nAxiom: F\nendlsystem\n", 2, 19, "an array's size must be"},
      {"Lsystem: 1\ndefine: { array a[2,2]; }\nAxiom: F\nF : { x = a[1]; } --> F\nendlsystem\n", 4, 11,
       "give an index for each"},
      {"Lsystem: 1\nAxiom: F\nF : { b[1] = 2; } --> F\nendlsystem\n", 3, 7, "'b' is not an array"},
  };
  for (const LocatedError& c : cases) expect_located(c);
  // An index outside the array is an error when it is evaluated, at the element.
  Grammar g = parse_ok("Lsystem: 1\nderivation length: 1\ndefine: { array a[2]; }\nAxiom: A(-1)\n"
                       "A(i) --> B(a[i])\nendlsystem\n");
  auto w = derive(g);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("index -1 is outside a's 0 .. 1"), std::string::npos) << w.error().format();
  EXPECT_EQ(w.error().loc.line, 5u);
  EXPECT_EQ(w.error().loc.column, 12u);
}

// ---- decomposition (CPFG manual 4.4) ----

TEST(CpfgDecomposition, AppliesAfterEveryStepAndItsResultsStayInTheWord) {
  // Depth 1 (cpfg's default): step 1: A -> A B, then B -> F C: AFC. Step 2: A -> A B (F and
  // C have no production), then B -> F C and the C of step 1 -> [+F]: AFCF[+F].
  const std::string model = "Lsystem: 1\nderivation length: 2\nAxiom: A\nA --> A B\ndecomposition:\nB --> F C\n"
                            "C --> [+F]\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "AFCF[+F]");
  // maximum depth: 2 decomposes what it decomposed once more; the homomorphism keeps its
  // own depth, and decomposition results are what the homomorphism (and the next step) see.
  const std::string deep = "Lsystem: 1\nderivation length: 2\nAxiom: A\nA --> A B\ndecomposition:\nmaximum depth: 2\n"
                           "B --> F C\nC --> [+F]\nhomomorphism:\nmaximum depth: 3\nF --> G\nendlsystem\n";
  EXPECT_EQ(derive_text(deep), "AF[+F]F[+F]");
  Grammar g = parse_ok(deep);
  EXPECT_EQ(g.decomposition_depth, 2);
  EXPECT_EQ(g.max_depth, 3);
  EXPECT_EQ(g.decomposition.size(), 2u);
  EXPECT_EQ(g.productions.size(), 1u);
  EXPECT_EQ(g.homomorphism.size(), 1u);
  EXPECT_EQ(drawn_text(g), "AG[+G]G[+G]");
}

TEST(CpfgDecomposition, TheAxiomIsDecomposedAndContextAndParametersWork) {
  // The axiom is decomposed before anything reads it (step 0); a parametric decomposition
  // with a condition, and one with context: B(n) splits while n > 1, into halves; a C
  // after a B becomes D.
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 0\nAxiom: B(4)\ndecomposition:\nmaximum depth: 5\n"
                        "B(n) : n > 1 --> B(n/2)B(n/2)\nendlsystem\n"),
            "B(1)B(1)B(1)B(1)");
  EXPECT_EQ(derive_text("Lsystem: 1\nderivation length: 1\nAxiom: B C C\nC --> C\ndecomposition:\nB < C --> D\n"
                        "endlsystem\n"),
            "BDC");
  // sylva's own format has the section too (default depth 16, as its homomorphism).
  EXPECT_EQ(derive_text("module: A B C\nderivation length: 2\naxiom: A B\nA -> A B\ndecomposition:\nB -> F C\n"
                        "C -> [+F]\n"),
            "AF[+F]F[+F]F[+F]");
}

TEST(CpfgDecomposition, ErrorsArePlacedAndItsGrowthIsBounded) {
  const LocatedError cases[] = {
      {"Lsystem: 1\nAxiom: F\nhomomorphism:\nF --> G\ndecomposition:\nG --> F\nendlsystem\n", 5, 1,
       "'decomposition:' must come before 'homomorphism:'"},
      {"Lsystem: 1\nAxiom: F\ndecomposition:\nseed: 3\nendlsystem\n", 4, 1, "takes no 'seed:'"},
      {"Lsystem: 1\nAxiom: F\ndecomposition: often\nendlsystem\n", 3, 16, "expected 'warnings' or 'no warnings'"},
  };
  for (const LocatedError& c : cases) expect_located(c);
  // A decomposition that doubles at every pass stops at --max-modules with an error.
  Grammar g = parse_ok("Lsystem: 1\nderivation length: 1\nAxiom: B\ndecomposition:\nmaximum depth: 40\nB --> BB\n"
                       "endlsystem\n");
  DeriveOptions o;
  o.max_modules = 1000;
  auto w = derive(g, o);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("max"), std::string::npos) << w.error().format();
  // The budget (16 × --max-modules written) is each step's, not the derivation's: 60
  // modules decomposed at each of 40 steps write far more than 16 × 100 in all, and pass.
  std::string sixty;
  for (int k = 0; k < 60; ++k) sixty += "B";
  Grammar many = parse_ok("Lsystem: 1\nderivation length: 40\nAxiom: " + sixty +
                          "\ndecomposition:\nB --> B\nendlsystem\n");
  DeriveOptions small;
  small.max_modules = 100;
  auto long_run = derive(many, small);
  ASSERT_TRUE(long_run.ok()) << long_run.error().format();
  EXPECT_EQ(long_run->size(), 60u);
}

// ---- statements (CPFG manual 3.2, 4.1) ----

TEST(CpfgStatements, BeforeAndAfterAProductionsConditionWithLocalsIfAndLoops) {
  // Step 1: A(1): m = 2, not > 3, so m = 1.5; k counts to 3: B(0) A(1.5) C(3); EndEach: i = 1.
  // Step 2: A(1.5): m = 3 -> 2.5: B(1) A(2.5) C(3); i = 2. Step 3: A(2.5): m = 5 > 3 -> 105.
  const std::string model =
      "Lsystem: 1\nderivation length: 3\nStart: { i = 0; };\nEndEach: {\n  i = i + 1;\n}\nAxiom: A(1)\n"
      "A(n) : { m = n * 2; if (m > 3) { m = m + 100; } else { m = m - 0.5; } } * { k = 0; while (k < 3) { k += 1; } }"
      " --> B(i) A(m) C(k)\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "B(0)B(1)B(2)A(105)C(3)C(3)C(3)");
  Grammar g = parse_ok(model);
  EXPECT_EQ(g.global_names, std::vector<std::string>{"i"});
}

TEST(CpfgStatements, DoWhileElseIfCompoundAssignmentAndBlocksOverSeveralLines) {
  // x: 0 -> do x += 2 while x < 7 -> 8; y: x > 10? no; x > 5? yes -> 2; z: 8 * 3 / 4 - 1 = 5.
  const std::string model =
      "Lsystem: 1\nAxiom: A\n"
      "A : {\n  x = 0;\n  do { x += 2; } while (x < 7);\n"
      "  if (x > 10) { y = 1; } else if (x > 5) { y = 2; } else { y = 3; }\n"
      "  z = x; z *= 3; z /= 4; z -= 1;\n} * --> B(x, y, z)\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "B(8,2,5)");
}

TEST(CpfgStatements, GlobalsPassFromBlocksToProductionsAndProductionsWriteThemInWordOrder) {
  // Start sets count = 10; each A, left to right, takes the count and increments it; End
  // doubles it, which the homomorphism (run after the derivation) reads.
  const std::string model =
      "Lsystem: 1\nStart: {count = 10;}\nEnd: {count = count * 2;}\nAxiom: A A A\n"
      "A : * {count = count + 1;} --> B(count)\nhomomorphism\nB(n) --> C(n, count)\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "B(11)B(12)B(13)");
  Grammar g = parse_ok(model);
  auto w = derive(g);
  ASSERT_TRUE(w.ok());
  ASSERT_EQ(w->globals.size(), 1u);
  EXPECT_EQ(w->globals[0], 26);
  auto drawn = interpret(g, *w);
  ASSERT_TRUE(drawn.ok());
  EXPECT_EQ(print_word(*drawn, g.symbols), "C(11,26)C(12,26)C(13,26)");
}

TEST(CpfgStatements, TheConditionReadsWhatTheBeforeStatementsComputed) {
  // The manual's own example (3.2): A(y) : { x=y/2; s=x*x; } s<10 --> B(x).
  const std::string model = "Lsystem: 1\nAxiom: A(4) A(8)\nA(y) : { x=y/2; s=x*x; } s<10 --> B(x)\nendlsystem\n";
  EXPECT_EQ(derive_text(model), "B(2)A(8)");
}

TEST(CpfgStatements, SrandInStartFixesTheDerivationsRandomNumbersWhateverTheSeed) {
  // The model: ran/bran after the condition, the seed from srand(SEED).
  const std::string model =
      "#define SEED 3\nLsystem: 1\nStart: {srand(SEED);}\nderivation length: 4\nAxiom: A(20)\n"
      "A(n) : n>1 {nl=floor(n*bran(5,16)); nr=n-nl-1;} --> F[+A(nl)][-A(nr)]\nA(n) : n<=1 --> F\nendlsystem\n";
  Grammar g = parse_ok(model);
  DeriveOptions seed_a, seed_b;
  seed_a.seed = 1;
  seed_b.seed = 99;
  auto a = derive(g, seed_a), b = derive(g, seed_b);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(print_word(*a, g.symbols), print_word(*b, g.symbols));  // srand wins over --seed, as in cpfg
  ParseOptions other;
  other.define_overrides["SEED"] = 4;
  Grammar h = parse_ok(model, other);
  auto c = derive(h);
  ASSERT_TRUE(c.ok());
  EXPECT_NE(print_word(*a, g.symbols), print_word(*c, h.symbols));
  // Every A(n) split into nl + nr + 1 = n: the word's A parameters and F count add up.
  for (const Module& m : c->modules) ASSERT_LE(m.param_count, 1);
}

TEST(CpfgStatements, ARunawayLoopStopsWithAnErrorAtTheLoopInBoundedTime) {
  const std::string model = "Lsystem: 1\nAxiom: A\nA : {x = 0; while (1) { x = x + 1; }} * --> B\nendlsystem\n";
  const std::string message = derive_text(model);
  EXPECT_NE(message.find("a loop ran more than 10000000 times"), std::string::npos) << message;
  Grammar g = parse_ok(model);
  auto w = derive(g);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().loc.line, 3u);
  EXPECT_EQ(w.error().loc.column, 13u);  // at the 'while'
}

TEST(CpfgStatements, MistakesInStatementsAreLocatedErrors) {
  const LocatedError cases[] = {
      {"Lsystem: 1\nAxiom: A\nA : {x = y;} * --> B\nendlsystem\n", 3, 10, "unknown name 'y'"},
      {"Lsystem: 1\nAxiom: A\nA : {x = 1} * --> B\nendlsystem\n", 3, 11, "expected ';'"},
      {"Lsystem: 1\nAxiom: A\nA : {if x > 1 { x = 1; }} * --> B\nendlsystem\n", 3, 9, "expected '('"},
      {"Lsystem: 1\nAxiom: A\nA : {x = 1; * --> B\nendlsystem\n", 3, 13, "expected an expression"},
      {"Lsystem: 1\nAxiom: A\nA : {do { x = 1; } (x < 2);} * --> B\nendlsystem\n", 3, 20, "expected 'while"},
      {"Lsystem: 1\nStart: {i = 0;} extra\nAxiom: A\nendlsystem\n", 2, 17, "after the 'Start:' block"},
      {"Lsystem: 1\nStart: {i = 0;}\nStart: {i = 1;}\nAxiom: A\nendlsystem\n", 3, 1, "given twice"},
  };
  for (const LocatedError& c : cases) expect_located(c);
}

// ---- vlab objects and view files ----

const char* const kVlabModel = "Lsystem: 1\nderivation length: 1\nAxiom: ;A\nA --> F+#F\nendlsystem\n";

TEST(VlabObject, AFolderIsReadThroughItsSpecificationsCpfgCommandAndItsViewFile) {
  ModelFolder folder;
  folder.write("plant.l", kVlabModel);
  folder.write("plant.v",
               "/* a view file */\nangle factor: 8\ninitial line width: 3 pixels\nline width increment: 0.5\n"
               "initial color: 3\ncolor increment: 2\nviewpoint: 0,0,1\nprojection: parallel\n"
               "tropism: T: 0 -1 0 I: 2 E: 0.1\n");
  folder.write("specifications", "plant.l\nplant.v\nplant.map\nignore:\n*\nMenu:\n\tEDIT plant.l\n"
                                 "generate:\n\tcpfg -w 400 300 -m plant.map -wt Plant plant.l plant.v\n");
  EXPECT_TRUE(is_grammar_path(folder.dir().string()));
  EXPECT_TRUE(is_grammar_path("tree.l"));
  EXPECT_TRUE(is_grammar_path("tree.lsys"));
  EXPECT_FALSE(is_grammar_path("tree.skel.json"));
  auto g = load_grammar(folder.dir().string());
  ASSERT_TRUE(g.ok()) << g.error().format();
  EXPECT_TRUE(g->cpfg);
  EXPECT_EQ(g->file, (folder.dir() / "plant.l").string());
  EXPECT_EQ(g->turtle.angle_deg, 45);            // 360 / 8
  EXPECT_DOUBLE_EQ(g->turtle.width, 3 * 0.05);   // pixels: 0.05 m of radius each
  EXPECT_EQ(g->turtle.width_increment, 0.5);
  EXPECT_EQ(g->turtle.initial_color, 3u);
  EXPECT_EQ(g->turtle.color_increment, 2u);
  ASSERT_EQ(g->turtle.view_tropisms.size(), 1u);
  EXPECT_FALSE(g->turtle.has_tropism) << "a view file's tropisms are cpfg's, not the ABOP header's";
  EXPECT_EQ(g->turtle.view_tropisms[0].vector[1], -1);  // T normalised times I, the factor at most 1 (cpfg)
  EXPECT_EQ(g->turtle.view_tropisms[0].elasticity, 0.1);
  EXPECT_EQ(g->turtle.view_tropisms[0].angle_deg, 0);
  // Several tropisms, ids in order: a weak one, and a diatropism with its step.
  folder.write("plant.v", "tropism: T: 0 -4 0 I: 0.5 E: 0.2\ntropism: T: 1 0 0 A: 90 E: 0.1 S: 0.05\n");
  auto weak = load_grammar(folder.dir().string());
  ASSERT_TRUE(weak.ok()) << weak.error().format();
  ASSERT_EQ(weak->turtle.view_tropisms.size(), 2u);
  EXPECT_EQ(weak->turtle.view_tropisms[0].vector[1], -0.5);  // (0, -4, 0) / 4 × 0.5
  EXPECT_EQ(weak->turtle.view_tropisms[1].angle_deg, 90);
  EXPECT_EQ(weak->turtle.view_tropisms[1].step, 0.05);
  // A world-unit style makes a width a diameter.
  folder.write("plant.v", "angle increment: 30\ninitial line width: 0.2 shaded\n");
  auto shaded = load_grammar(folder.dir().string());
  ASSERT_TRUE(shaded.ok()) << shaded.error().format();
  EXPECT_EQ(shaded->turtle.angle_deg, 30);
  EXPECT_DOUBLE_EQ(shaded->turtle.width, 0.1);
  EXPECT_EQ(shaded->turtle.initial_scale, 1);
  EXPECT_EQ(shaded->turtle.scale_multiplier, 1);
  // The turtle's scale (manual 8.1.1, 6.3): its initial value and @Di / @Dd's multiplier.
  folder.write("plant.v", "initial scale: 3\nscale multiplier: 0.5\n");
  auto scaled = load_grammar(folder.dir().string());
  ASSERT_TRUE(scaled.ok()) << scaled.error().format();
  EXPECT_EQ(scaled->turtle.initial_scale, 3);
  EXPECT_EQ(scaled->turtle.scale_multiplier, 0.5);
  folder.write("plant.v", "angle factor: 8\nscale multiplier: 0\n");
  auto zero = load_grammar(folder.dir().string());
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.error().loc.line, 2u);
  EXPECT_NE(zero.error().message.find("must be a non-zero number"), std::string::npos) << zero.error().message;
  EXPECT_TRUE(shaded->colours.empty()) << "no plant.map in the folder: cpfg's defaults, as cpfg goes on";
}

// Contour functions (CPFG manual 5.5; cpfg's curveXYZ.cpp): the view file's `curve: file
// [samples]` lines, ids in order; curveX/Y/Z(id, t) the point at the fraction t of the
// curve's sampled length, curveGAL(id) that length. A straight B-spline from (0, 0) to (3, 0)
// (its ends tripled, as cuspy writes them): length 3, its middle at x = 1.5.
TEST(VlabObject, ContourFunctionsMeasureTheViewFilesCurves) {
  ModelFolder folder;
  folder.write("specifications", "generate:\n\tcpfg plant.l plant.v\n");
  folder.write("line.con", "version: 1.4\ncontact: 0 0 0\nend: 0 0 0\nheading: 0 1 0\nup: 0 0 -1\nsize: 1\n"
                           "points: 4\nrange: 0.0 1.0\ndimension: 4\ntype: bspline\n"
                           "0 0 0 3\n1 0 0 1\n2 0 0 1\n3 0 0 3\n");
  folder.write("plant.v", "angle factor: 8\ncurve: line.con\ncurve: line.con 2\n");
  folder.write("plant.l", "Lsystem: 1\nderivation length: 0\nStart: {L = curveGAL(1);}\n"
                          "Axiom: A(L, curveX(1, 0.5), curveX(1, -1), curveX(1, 7), curveY(1, 0.3), curveGAL(2))\n"
                          "endlsystem\n");
  auto g = load_grammar(folder.dir().string());
  ASSERT_TRUE(g.ok()) << g.error().format();
  ASSERT_EQ(g->program.curves.size(), 2u);
  auto w = derive(*g);
  ASSERT_TRUE(w.ok()) << w.error().message;
  const double* p = w->params_of(w->modules[0]);
  EXPECT_NEAR(p[0], 3, 1e-12);
  EXPECT_NEAR(p[1], 1.5, 2e-3);
  EXPECT_NEAR(p[2], 0, 1e-12);  // t below 0 is the start
  EXPECT_NEAR(p[3], 3, 1e-9);   // above 1 the end
  EXPECT_EQ(p[4], 0);
  EXPECT_NEAR(p[5], 3, 1e-12) << "two samples: the chord, here the line itself";
  folder.write("plant.l", "Lsystem: 1\nAxiom: A(curveX(3, 0.5))\nendlsystem\n");
  auto three = load_grammar(folder.dir().string());
  std::string message = three.ok() ? "" : three.error().message;
  if (three.ok()) {
    auto derived = derive(*three);
    ASSERT_FALSE(derived.ok());
    message = derived.error().message;
  }
  EXPECT_NE(message.find("the curve id is 1 to 2"), std::string::npos) << message;
  folder.write("plant.v", "curve: line.con 1\n");
  auto one = load_grammar(folder.dir().string());
  ASSERT_FALSE(one.ok());
  EXPECT_EQ(one.error().loc.column, 17u);
}

// vlab's panel.l: a slider with "message: d NAME %d scale" sets NAME to value / scale, so its
// range is min / scale .. max / scale in steps of 1 / scale; other items are left out.
TEST(VlabObject, PanelSlidersGiveTheirDefinesRanges) {
  const auto sliders = read_panel_sliders(
      "target: Lsystem\n\ntype: LABEL\nname: GENERAL\ncolor: 255,255,0\norigin: 129 0\n\n"
      "type: SLIDER\nname: Steps\ncolors: 255,255,255 255,0,0\norigin: 20 30\nmin/max: 0 800\nvalue: 650\n"
      "message: d STEPS %d 1\n\ntype: SLIDER\nname: Width\nmin/max: 5 40\nvalue: 10\nmessage: d WIDTH %d 10\n\n"
      "type: BUTTON\nname: Grid\nvalue: 1\nmessage: d GRID 1 1\n\ntype: SLIDER\nname: Odd\nmin/max: 9 1\n"
      "message: d ODD %d 1\n");
  ASSERT_EQ(sliders.size(), 2u);
  EXPECT_EQ(sliders[0].define, "STEPS");
  EXPECT_EQ(sliders[0].label, "Steps");
  EXPECT_EQ(sliders[0].max, 800);
  EXPECT_EQ(sliders[0].value, 650);
  EXPECT_EQ(sliders[1].define, "WIDTH");
  EXPECT_DOUBLE_EQ(sliders[1].min, 0.5);
  EXPECT_DOUBLE_EQ(sliders[1].max, 4);
  EXPECT_DOUBLE_EQ(sliders[1].step, 0.1);
  EXPECT_DOUBLE_EQ(sliders[1].value, 1);
  EXPECT_TRUE(read_panel_sliders("type: SLIDER\nmin/max: 0 1\nmessage: n 4 1 -1 %d\n").empty());
}

// The colours (docs/cpfg.md "Colours"): `-m` a colour map of 256 RGB bytes, `-M` a material
// file of 15-byte records (index, transparency, ambient, diffuse, emissive, specular,
// shininess); the material file wins. A file of the wrong size is an error at its option.
TEST(VlabObject, TheColourMapOrMaterialFileGivesTheColours) {
  ModelFolder folder;
  folder.write("plant.l", kVlabModel);
  folder.write("plant.v", "angle factor: 8\n");
  std::string map(768, '\0');
  for (int i = 0; i < 256; ++i) map[3 * i] = static_cast<char>(i), map[3 * i + 2] = static_cast<char>(255 - i);
  folder.write("plant.map", map);
  folder.write("specifications", "generate:\n\tcpfg -m plant.map plant.l plant.v\n");
  auto g = load_grammar(folder.dir().string());
  ASSERT_TRUE(g.ok()) << g.error().format();
  ASSERT_EQ(g->colours.size(), 256u);
  EXPECT_EQ(g->colours[51].index, 51u);
  EXPECT_DOUBLE_EQ(g->colours[51].srgb[0], 0.2);
  EXPECT_DOUBLE_EQ(g->colours[51].srgb[1], 0.0);
  EXPECT_DOUBLE_EQ(g->colours[51].srgb[2], 0.8);
  EXPECT_EQ(g->colours[51].specular, 1);
  // Two records: index 7 (diffuse 255, 51, 0; specular 0, 102, 0), then 2 (all zero).
  std::string mat(30, '\0');
  mat[0] = 7, mat[5] = static_cast<char>(255), mat[6] = 51, mat[12] = 102;
  mat[15] = 2;
  folder.write("plant.mat", mat);
  folder.write("specifications", "generate:\n\tcpfg -m plant.map -M plant.mat plant.l plant.v\n");
  auto m = load_grammar(folder.dir().string());
  ASSERT_TRUE(m.ok()) << m.error().format();
  ASSERT_EQ(m->colours.size(), 2u);
  EXPECT_EQ(m->colours[0].index, 7u);
  EXPECT_DOUBLE_EQ(m->colours[0].srgb[0], 1.0);
  EXPECT_DOUBLE_EQ(m->colours[0].srgb[1], 0.2);
  EXPECT_DOUBLE_EQ(m->colours[0].specular, 0.4);
  EXPECT_EQ(m->colours[1].index, 2u);
  folder.write("plant.mat", mat.substr(0, 29));
  auto bad = load_grammar(folder.dir().string());
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().loc.line, 2u);
  EXPECT_EQ(bad.error().loc.column, 20u);  // at -M
  EXPECT_NE(bad.error().format().find("records of 15 bytes"), std::string::npos) << bad.error().format();
}

TEST(VlabObject, WhatSylvaCannotFollowIsAnErrorAtItsPlace) {
  ModelFolder folder;
  folder.write("plant.l", kVlabModel);
  folder.write("plant.v", "angle factor: 8\n");
  struct Case {
    const char* specifications;
    const char* view;
    const char* file;  // the file the error is in
    uint32_t line, column;
    const char* says;
  };
  const Case cases[] = {
      {"run:\n\tcpfg -e field.e plant.l plant.v\n", "angle factor: 8\n", "specifications", 2, 7, "environment file 'field.e'"},
      {"run:\n\tcpfg -Q plant.l plant.v\n", "angle factor: 8\n", "specifications", 2, 7, "unknown cpfg option '-Q'"},
      {"run:\n\tcpfg plant.l\n", "angle factor: 8\n", "specifications", 2, 2, "the model and the view file"},
      {"run:\n\tcpfg -w 400\n", "angle factor: 8\n", "specifications", 2, 7, "needs 2 argument"},
      {"run:\n\tlpfg plant.l plant.v\n", "angle factor: 8\n", "specifications", 0, 0, "no cpfg command"},
      {"run:\n\tcpfg plant.l plant.v\n", "angle factor: 0\n", "plant.v", 1, 15, "must not be 0"},
      {"run:\n\tcpfg plant.l plant.v\n", "initial line width: wide\n", "plant.v", 1, 21, "needs a number"},
      {"run:\n\tcpfg plant.l plant.v\n", "tropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\ntropism: T: 0 1 0\n", "plant.v", 9, 1, "more than 8 tropisms"},
      {"run:\n\tcpfg plant.l plant.v\n", "scale multiplier: 0\n", "plant.v", 1, 19, "must be a non-zero number"},
      {"run:\n\tcpfg plant.l plant.v\n", "tropism: T: 0 0 0 E: 0.1\n", "plant.v", 1, 9, "must not be 0"},
      {"run:\n\tcpfg plant.l missing.v\n", "", "missing.v", 0, 0, "cannot open"},
  };
  for (const Case& c : cases) {
    folder.write("specifications", c.specifications);
    folder.write("plant.v", c.view);
    auto g = load_grammar(folder.dir().string());
    ASSERT_FALSE(g.ok()) << c.specifications << c.view;
    const Diagnostic& d = g.error();
    EXPECT_NE(d.file.find(c.file), std::string::npos) << d.format();
    EXPECT_EQ(d.loc.line, c.line) << d.format();
    EXPECT_EQ(d.loc.column, c.column) << d.format();
    EXPECT_NE(d.message.find(c.says), std::string::npos) << d.format();
  }
  ModelFolder empty("_empty");
  auto none = load_grammar(empty.dir().string());
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("not a vlab object"), std::string::npos) << none.error().format();
}

// The view file's functions (CPFG manual 5.5, 8.1.6; docs/cpfg.md "Functions"): func(id, x)
// is the curve's y where its x is x, x clamped to [0, 1]. The S curve below has control points
// (0, 0), (1/3, 0), (2/3, 1), (1, 1): a cubic Bézier (four points of cpfg's open B-spline)
// with x(t) = t and y(t) = 3t² − 2t³, so y(0.25) = 0.15625, y(0.5) = 0.5.
const char* const kSCurve = "0 0\n0.3333333333 0\n0.6666666667 1\n1 1\n";

TEST(VlabObject, TheViewFilesFunctionsAnswerFunc) {
  ModelFolder folder;
  folder.write("specifications", "generate:\n\tcpfg plant.l plant.v\n");
  folder.write("curve.func", std::string("fver 1 1\nname: curve\nsamples: 0\nflip: off\npoints: 4\n") + kSCurve);
  // The older format takes the view file's samples: 3 values, at 0, 0.5 and 1, joined by lines.
  folder.write("old.func", std::string("range: 0 1\npoints: 4\n") + kSCurve);
  folder.write("plant.v", "angle factor: 8\nfunction: curve.func\nfunction: old.func 3\n");
  folder.write("plant.l", "Lsystem: 1\nderivation length: 1\nAxiom: A(0.25)\n"
                          "A(x) --> B(func(1, x), func(1, 0.5), func(2, x), func(1, -3), func(1, 7))\nendlsystem\n");
  auto g = load_grammar(folder.dir().string());
  ASSERT_TRUE(g.ok()) << g.error().format();
  auto w = derive(*g);
  ASSERT_TRUE(w.ok());
  ASSERT_EQ(w->size(), 1u);
  const double* p = w->params_of(w->modules[0]);
  EXPECT_NEAR(p[0], 0.15625, 2e-3);  // within cpfg's bisection tolerance of 0.001 in x
  EXPECT_NEAR(p[1], 0.5, 2e-3);
  EXPECT_NEAR(p[2], 0.25, 2e-3);     // the table's line between y(0) = 0 and y(0.5) = 0.5
  EXPECT_NEAR(p[3], 0, 2e-3);        // x below 0 is 0
  EXPECT_NEAR(p[4], 1, 2e-3);        // x above 1 is 1
  // A function set names its functions: each name is a macro for its id (cpfg's -D), which
  // the model may define again. A control point's third number repeats it.
  folder.write("shapes.fset", std::string("funcgalleryver 1 1\nitems: 2\n") +
                                  "fver 1 1\nname: LINE\nsamples: 0\nflip: off\npoints: 4\n0 0 2\n0.5 0.5\n1 1\n1 1\n" +
                                  "fver 1 1\nname: S\nsamples: 0\nflip: off\npoints: 4\n" + kSCurve);
  folder.write("plant.v", "function set: shapes.fset\n");
  folder.write("plant.l", "#define LINE 1\nLsystem: 1\nderivation length: 1\nAxiom: A(0.25)\n"
                          "A(x) --> B(func(S, x), func(LINE, x))\nendlsystem\n");
  auto set = load_grammar(folder.dir().string());
  ASSERT_TRUE(set.ok()) << set.error().format();
  ASSERT_EQ(set->program.functions.size(), 2u);
  EXPECT_EQ(set->program.functions[1].name, "S");
  EXPECT_EQ(set->program.functions[0].x.size(), 5u);  // (0, 0) twice
  auto sw = derive(*set);
  ASSERT_TRUE(sw.ok());
  EXPECT_NEAR(sw->params_of(sw->modules[0])[0], 0.15625, 2e-3);
  // An id no function has, a file that cannot be read, a malformed one: errors at their place.
  folder.write("plant.l", "Lsystem: 1\nderivation length: 1\nAxiom: A(0.25)\nA(x) --> B(func(3, x))\nendlsystem\n");
  auto three = load_grammar(folder.dir().string());
  ASSERT_TRUE(three.ok()) << three.error().format();
  auto bad = derive(*three);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("the function id is 1 to 2"), std::string::npos) << bad.error().message;
  EXPECT_EQ(bad.error().loc.line, 4u);
  folder.write("plant.v", "angle factor: 8\n\nfunction: missing.func 10\n");
  auto missing = load_grammar(folder.dir().string());
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().loc.line, 3u);
  EXPECT_NE(missing.error().message.find("cannot read the function file 'missing.func'"), std::string::npos);
  folder.write("few.func", "fver 1 1\nname: few\nsamples: 10\nflip: off\npoints: 3\n0 0\n0.5 0.5\n1 1\n");
  folder.write("plant.v", "function: few.func\n");
  auto few = load_grammar(folder.dir().string());
  ASSERT_FALSE(few.ok());
  ASSERT_EQ(few.error().notes.size(), 1u);
  EXPECT_NE(few.error().notes[0].file.find("few.func"), std::string::npos);
  EXPECT_EQ(few.error().notes[0].loc.line, 5u);
  EXPECT_NE(few.error().notes[0].message.find("at least 4"), std::string::npos);
  // Without a vlab object's view file there are no functions.
  EXPECT_NE(parse_error("Lsystem: 1\nAxiom: F(func(1, 0.5))\nendlsystem\n").message.find("has no functions"), std::string::npos);
}

// What the view file says as cpfg's reader reads it: `A:90` is `A: 90` (its tokens split at
// ':'), a line style cpfg does not know keeps the style, `pixel` is `p`, and a homomorphism
// may be as deep as vlab's models ask (`maximum depth: 3000`).
TEST(VlabObject, TheViewFileIsReadAsCpfgReadsIt) {
  ModelFolder folder;
  folder.write("specifications", "generate:\n\tcpfg plant.l plant.v\n");
  folder.write("plant.l", "Lsystem: 1\nderivation length: 1\nAxiom: A\nhomomorphism\nmaximum depth: 3000\nendlsystem\n");
  folder.write("plant.v", "tropism: T: 1 0 0 A:90 E:0.1\ninitial line width: 2 pixel\nline style: wireframe\n");
  auto g = load_grammar(folder.dir().string());
  ASSERT_TRUE(g.ok()) << g.error().format();
  ASSERT_EQ(g->turtle.view_tropisms.size(), 1u);
  EXPECT_EQ(g->turtle.view_tropisms[0].angle_deg, 90);
  EXPECT_EQ(g->turtle.view_tropisms[0].elasticity, 0.1);
  EXPECT_DOUBLE_EQ(g->turtle.width, 2 * 0.05);  // pixels, kept by the unknown line style
  EXPECT_EQ(g->max_depth, 3000);
  // Without a `p...` word cpfg's reader draws the width in world units (a diameter), where
  // the manual's table says pixels; no line at all: 1 pixel.
  for (const char* view : {"initial line width: 0.2\n", "initial line width: 0.2 wide\n", "initial line width: 0.2 s\n"}) {
    folder.write("plant.v", view);
    auto w = load_grammar(folder.dir().string());
    ASSERT_TRUE(w.ok()) << w.error().format();
    EXPECT_DOUBLE_EQ(w->turtle.width, 0.1) << view;
  }
  // cpfg's double-sided surfaces: a second initial colour (the back's) and colour increment
  // (@; and @,'s); a back side in its own colour only with a material file, as cpfg draws it.
  folder.write("plant.v", "initial color: 3 7\ncolor increment: 2 5\n");
  auto sides = load_grammar(folder.dir().string());
  ASSERT_TRUE(sides.ok()) << sides.error().format();
  EXPECT_EQ(sides->turtle.initial_color, 3u);
  EXPECT_EQ(sides->turtle.initial_back_color, 7u);
  EXPECT_EQ(sides->turtle.color_increment, 2u);
  EXPECT_EQ(sides->turtle.color_increment_back, 5u);
  EXPECT_FALSE(sides->turtle.double_sided) << "no material file: both sides in the front's colour";
  folder.write("plant.mat", std::string(15, '\0'));
  folder.write("specifications", "generate:\n\tcpfg -M plant.mat plant.l plant.v\n");
  auto with_materials = load_grammar(folder.dir().string());
  ASSERT_TRUE(with_materials.ok()) << with_materials.error().format();
  EXPECT_TRUE(with_materials->turtle.double_sided);
  folder.write("plant.v", "initial color: 3 x\n");  // not a number: one colour, as cpfg's fscanf
  auto one = load_grammar(folder.dir().string());
  ASSERT_TRUE(one.ok()) << one.error().format();
  EXPECT_FALSE(one->turtle.double_sided);
  folder.write("plant.v", "initial color: 3 -7\n");
  auto negative = load_grammar(folder.dir().string());
  ASSERT_FALSE(negative.ok());
  EXPECT_EQ(negative.error().loc.column, 18u);
  folder.write("plant.v", "angle factor: 4\n");
  auto none = load_grammar(folder.dir().string());
  ASSERT_TRUE(none.ok()) << none.error().format();
  EXPECT_DOUBLE_EQ(none->turtle.width, 0.05);
}

// ---- chapter 5 functions ----

TEST(CpfgFunctions, RoundingAndSignAreExact) {
  EXPECT_EQ(derive_text("axiom: F(fabs(-2.5)) F(trunc(-2.7)) F(trunc(2.7)) F(sign(-3)) F(sign(0)) F(sign(4))\n"),
            "F(2.5)F(-2)F(2)F(-1)F(0)F(1)");
}

// Draws n values of `expr` through the axiom of a one-step grammar with `seed`.
std::vector<double> draws(const std::string& expr, int n, uint64_t seed = 7) {
  std::string axiom;
  for (int k = 0; k < n; ++k) axiom += "A(" + expr + ")";
  Grammar g = parse_ok("seed: " + std::to_string(seed) + "\nderivation length: 0\naxiom: " + axiom + "\n");
  auto w = derive(g);
  EXPECT_TRUE(w.ok());
  return w.ok() ? w->params : std::vector<double>{};
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

TEST(CpfgFunctions, RandomFunctionsDrawFromTheirDistributionsAndTheSeed) {
  constexpr int n = 4000;
  // ran(x): uniform on [0, x]; mean x/2, standard error x/sqrt(12 n) = 0.0091 for x = 2.
  const std::vector<double> ran = draws("ran(2)", n);
  for (double x : ran) EXPECT_TRUE(x >= 0 && x <= 2) << x;
  EXPECT_NEAR(mean_of(ran), 1.0, 5 * 0.0091);
  // nran(m, s): mean m, standard error s/sqrt(n) = 0.047 for s = 3.
  EXPECT_NEAR(mean_of(draws("nran(10, 3)", n)), 10.0, 5 * 0.047);
  // bran(a, b): Beta(a, b), mean a/(a+b) = 0.25 for (2, 6), variance ab/((a+b)^2 (a+b+1)) = 0.0208,
  // standard error 0.0023; and for a < 1 too (Beta(0.5, 0.5): mean 0.5, sd 0.354, se 0.0056).
  const std::vector<double> beta = draws("bran(2, 6)", n);
  for (double x : beta) EXPECT_TRUE(x > 0 && x < 1) << x;
  EXPECT_NEAR(mean_of(beta), 0.25, 5 * 0.0023);
  EXPECT_NEAR(mean_of(draws("bran(0.5, 0.5)", n)), 0.5, 5 * 0.0056);
  // biran(n, p): Binomial(20, 0.3): integers in [0, 20], mean 6, standard error sqrt(4.2/n) = 0.032.
  const std::vector<double> binomial = draws("biran(20, 0.3)", n);
  for (double x : binomial) EXPECT_TRUE(x >= 0 && x <= 20 && x == std::floor(x)) << x;
  EXPECT_NEAR(mean_of(binomial), 6.0, 5 * 0.032);
  // The seed decides every draw.
  EXPECT_EQ(draws("bran(2, 6)", 5, 3), draws("bran(2, 6)", 5, 3));
  EXPECT_NE(draws("bran(2, 6)", 5, 3), draws("bran(2, 6)", 5, 4));
}

TEST(CpfgFunctions, ArgumentsOutsideTheirDomainAreLocatedErrors) {
  EXPECT_NE(derive_text("axiom: A\nA -> B(bran(0, 1))\n").find("bran(a, b) needs a > 0"), std::string::npos);
  EXPECT_NE(derive_text("axiom: A\nA -> B(biran(2.5, 0.5))\n").find("integer n"), std::string::npos);
  EXPECT_NE(derive_text("axiom: A\nA -> B(biran(1e7, 0.5))\n").find("integer n"), std::string::npos);
  EXPECT_NE(derive_text("axiom: A\nA -> B(biran(3, 1.5))\n").find("p from 0 to 1"), std::string::npos);
}

}  // namespace
}  // namespace sylva::lsys
