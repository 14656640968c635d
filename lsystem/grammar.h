// grammar.h — a parsed and compiled grammar (docs/spec/grammar.md), ready to derive.
//
// parse_grammar() reads .lsys text once: it checks UTF-8, strips comments, joins
// continuation lines, evaluates #defines (with overrides) and header directives,
// tokenises module strings with the declared multi-character names, and compiles every
// expression to bytecode (expr.h). Nothing is re-parsed during derivation.
// Errors: the first problem found, as a Diagnostic with file, line and column.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/diagnostic.h"
#include "lsystem/cpfg_contour.h"
#include "lsystem/cpfg_surface.h"
#include "lsystem/expr.h"
#include "lsystem/word.h"

namespace sylva::lsys {

// A module in a context pattern or predecessor: symbol, arity, and the slot of its first
// formal parameter in the production's slot array.
struct PatternModule {
  SymbolId symbol;
  uint16_t arity;
  uint32_t first_slot;
};

// A module of a successor: symbol and the range of its argument expressions.
struct SuccessorModule {
  SymbolId symbol;
  uint16_t arg_count;
  uint32_t first_arg;  // index into Successor::args
};

struct Successor {
  std::vector<SuccessorModule> modules;
  std::vector<Expr> args;
  bool all_constant = true;  // every argument is a constant: `prebuilt` holds the result
  Word prebuilt;             // the successor as a word (only when all_constant)
};

struct Production {
  SourceLoc loc;            // where the production starts
  std::string label;        // "p1", or empty
  std::string text;         // the production as written (for messages)
  PatternModule predecessor;
  // A cpfg file's strict predecessor of several modules (docs/cpfg.md): the modules after
  // the first, matched in the word right after it, no module passed over; empty elsewhere.
  std::vector<PatternModule> predecessor_tail;
  std::vector<PatternModule> left_context;   // in reading order
  std::vector<PatternModule> right_context;  // may contain [ and ]
  uint32_t slot_count = 0;                   // formal parameters in all patterns, then locals
  Expr before;                               // cpfg statements run on a match, before the condition
  Expr condition;                            // kind kNone: always
  Expr after;                                // cpfg statements run when the production applies
  Expr probability;                          // kind kNone: not stochastic
  Successor successor;
  // New context (lpfg's `<<` and `>>`, docs/grammar-notes.md "Passes"): the context is matched
  // in the word this pass has already written, not in the word before it. `<<` only in a
  // forward pass, `>>` only in a backward one.
  bool new_left = false, new_right = false;
  uint32_t pass = 0;                         // the pass it belongs to (Grammar::passes)
  uint32_t lsystem = 0;                      // a cpfg file's L-system it belongs to (Grammar::lsystem_labels)
  bool has_context() const { return !left_context.empty() || !right_context.empty(); }
  bool has_statements() const { return before.kind != Expr::Kind::kNone || after.kind != Expr::Kind::kNone; }
};

// One `tropism:` line of a cpfg view file (CPFG manual 8.1.8; docs/cpfg.md): its id is its
// place plus 1. `vector` is T normalised times the intensity (the factor clamped to [-1, 1],
// as cpfg's read_movement); `angle_deg` the angle A the shoots seek to T (0: orthotropism).
struct ViewTropism {
  double vector[3] = {0, 0, 0};
  double angle_deg = 0;
  double elasticity = 0;  // E: the initial elasticity
  double step = 0;        // S: @Ti and @Td's step without a value
  // A `torque:` line (CPFG manual 8.1.8): it twists the turtle about its heading, its up
  // vector turned with the projection of `vector` (docs/cpfg.md), and does not bend it.
  // Torques and tropisms share the ids, in the view file's order.
  bool torque = false;
};
inline constexpr size_t kMaxViewTropisms = 8;

// Turtle settings from the header (docs/spec/grammar.md "Header directives").
struct TurtleDefaults {
  double angle_deg = 90;
  double width = 0.05;  // initial radius in metres
  double width_decrement = 0.7;
  double step = 1;
  bool has_tropism = false;
  double tropism[3] = {0, 0, 0};
  double tropism_e = 0;
  // cpfg's view-file settings (docs/cpfg.md), read only for a cpfg file: a line width w
  // becomes a radius of w * width_scale; `#` and `!` add and take width_increment (in line
  // widths), `;` and `,` add and take color_increment.
  double width_scale = 0.05;
  double width_increment = 0;
  uint32_t color_increment = 1;
  uint32_t initial_color = 0;  // the material index the turtle starts with (a view file's)
  // cpfg's double-sided surfaces (CPFG manual 6.3, 8.1.1: `initial color: front back`, drawn
  // so by cpfg with a material file): every leaf gets the turtle's back colour as its back
  // material (docs/cpfg.md "Two-sided surfaces"); @; and @, step it by color_increment_back.
  bool double_sided = false;
  uint32_t initial_back_color = 128;  // cpfg's default (interpret.c)
  uint32_t color_increment_back = 1;
  // The turtle's scale (CPFG manual 6.3, 8.1.1): `initial scale:` and `scale multiplier:`,
  // which @D, @Di and @Dd change; lengths and set widths are multiplied by it.
  double initial_scale = 1;
  double scale_multiplier = 1;
  // A cpfg file's tropisms (the view file's `tropism:` lines, ids 1, 2, ...): the turtle
  // bends by all of them before every move, as cpfg does (docs/cpfg.md). sylva's own
  // `tropism:` header (has_tropism) stands for one orthotropism in a cpfg file without them.
  std::vector<ViewTropism> view_tropisms;
  // The points around a contour (a view file's `contour sides:`, or 2^(n + 1) for its
  // `polygonization level: n`; cpfg's default 8); @!(n) sets it for the turtle.
  int contour_sides = 8;
  // A view file's `interpretation past %:` (CPFG manual 8.1.1, on by default): a % left in
  // the word is passed over; off, the turtle skips the rest of its branch.
  bool interpret_past_cut = true;
};

// A file a cpfg grammar read with #include (lsystem/cpfg_preprocessor.h).
struct IncludedFile {
  std::string path;                          // as opened, for messages
  std::shared_ptr<const std::string> text;   // for caret lines
  SourceLoc included_at;                     // the #include line that read it
};

// A #define after overrides.
struct Define {
  std::string name;
  double value;
  SourceLoc loc;
  bool overridden = false;
};

struct Grammar {
  std::string file;                          // as given, for messages
  std::shared_ptr<const std::string> text;   // the source, for caret lines
  // A cpfg model file (is_cpfg_text; docs/cpfg.md): the turtle reads cpfg's symbols.
  bool cpfg = false;
  // A vlab object's predefined surfaces (its view file's `surface:` lines): `~X` draws them.
  std::vector<CpfgSurface> surfaces;
  // Its contours (the view file's `contour:` lines): `@#(id)` sweeps them along cylinders.
  std::vector<CpfgContour> contours;
  // A vlab object whose environmental program (`cpfg -e file.e`) sylva has built in: its `?E`
  // queries are answered by that program's rule (docs/cpfg.md "Environmental programs"), not
  // by light (core/grow/vlab_enviro.h answers them).
  // honda81: radius, the spec file's; three_d, its `3d case: on` (else x and z are compared).
  struct Honda81 {
    double radius = 0;
    bool three_d = false;
  };
  // chiba (Chiba et al. 1994's light on leaf balls), from its spec file: light from the
  // `source direction: x y z intensity` lines, or else from a sky of `number of samples:`
  // directions (rounded up to 8 * 4^k, k < kMaxLevel), the lower hemisphere's weighted
  // `lower to upper ratio:` against the upper's 1, or the CIE overcast sky (`use CIE
  // formula: yes`); each ball met dims it by `transmittance:`.
  struct Chiba {
    static constexpr int kMaxLevel = 7;  // 8 * 4^6 = 32768 sky directions at most
    struct Source {
      double direction[3] = {0, 1, 0};
      double intensity = 1;
    };
    std::vector<Source> sources;
    double samples = 20;
    double lower_to_upper = 0.7;
    bool cie_sky = false;
    double transmittance = 0.6;
    double radius = 25;          // a ball's radius where ?E(r) has r <= 0
    double beam_radius = 0;      // the ray's width, in the asking ball's radii (1 with estimate_area, as chiba sets it)
    bool estimate_area = false;  // `estimate intersection area: on`: dim by the discs' overlap
  };
  struct Environment {
    std::string program;  // "honda81" or "chiba"
    Honda81 honda81;
    Chiba chiba;
    // The .e file's `turtle position:` conversions: cpfg writes the positions with them to a
    // program it talks to through files or pipes (none through memory), so they are rounded so.
    std::vector<std::string> position_formats;
  };
  std::optional<Environment> environment;
  // A vlab object's colours (docs/cpfg.md "Colours"): its colour map (`cpfg -m`, 256 sRGB
  // triples) or material file (`-M`: each record's diffuse colour, and its specular's
  // brightest channel as the lobe's weight), by colour index, which is the turtle's material
  // index. Empty: none given (the scene's table, then sylva's defaults).
  struct Colour {
    uint32_t index = 0;
    double srgb[3] = {0, 0, 0};  // 0..1, sRGB-encoded as the files store them
    double specular = 1;         // the Blinn–Phong lobe's weight (a colour map's: sylva's default)
  };
  std::vector<Colour> colours;
  std::vector<IncludedFile> includes;        // SourceLoc::file k > 0 is includes[k - 1]
  // A cpfg file's global variables (assigned in its blocks) and its blocks (CPFG manual 4.1):
  // Start before the axiom, StartEach and EndEach around every step, End after the last.
  std::vector<std::string> global_names;     // a global's index is its place here
  std::vector<double> global_initial;        // their values before the Start block (arrays' initialisers; else 0)
  Expr start_block, start_each_block, end_each_block, end_block;  // kind kNone: none
  // The sub-L-systems' blocks (CPFG manual 7.2), by kind (Start, StartEach, EndEach, End),
  // in file order: each kind runs after the main L-system's, as cpfg's Evaluate*Statements
  // run every L-system's in its list. The globals are one set for the whole file.
  std::vector<Expr> sub_blocks[4];
  SymbolTable symbols;
  std::vector<Define> defines;
  TurtleDefaults turtle;
  uint64_t seed = 1;
  int64_t steps = 1;
  int max_depth = 16;        // homomorphism recursion limit
  // Whether interpret() counts the modules left expandable at max_depth (the front ends warn):
  // always in sylva's format; in a cpfg file only after 'homomorphism: warnings' (manual 4.3.1).
  bool depth_warnings = true;
  Word axiom;                 // the start word (random arguments: drawn with `seed`)
  SourceLoc axiom_loc;
  // Set when the axiom draws random numbers (`axiom: F(uniform(1,2))`): derive() then
  // evaluates it again from the effective seed's axiom stream (see axiom_rng).
  std::optional<Successor> axiom_successor;
  Program program;           // all compiled expressions
  std::vector<Production> productions;
  std::vector<Production> homomorphism;
  // Decomposition productions (CPFG manual 4.4): applied recursively, up to
  // decomposition_depth passes, to the axiom and after every step's rewriting, before
  // EndEach; their results stay in the word.
  std::vector<Production> decomposition;
  int decomposition_depth = 16;  // a cpfg file's default: 1, as its homomorphism's
  std::vector<uint8_t> ignored;  // by symbol id: skipped when matching context
  // A derivation step rewrites the word once per pass, in file order (`pass: forward` /
  // `pass: backward` lines split the productions; without them there is one forward pass).
  // A forward pass writes the new word left to right, a backward one right to left, so new
  // context reaches across the whole word in one step (docs/grammar-notes.md "Passes").
  struct Pass {
    bool backward = false;
    SourceLoc loc;                                  // its `pass:` line ({0, 0}: the implicit one)
    std::vector<std::vector<uint32_t>> by_symbol;   // its productions by predecessor, in file order
  };
  std::vector<Pass> passes{1};
  // Index lists by predecessor symbol, in file order.
  std::vector<std::vector<uint32_t>> homomorphism_by_symbol;
  std::vector<std::vector<uint32_t>> decomposition_by_symbol;
  bool uses_random = false;   // any stochastic production or random function
  bool uses_context = false;  // any production with left or right context
  bool uses_files = false;    // a cpfg file's statements call fopen or fprintf (EvalContext::files)
  // % appears in a successor or the axiom. In sylva's format the cut is made as the word is
  // written; in a cpfg file the % stays in the word and cuts when the next step reads it, as
  // cpfg's generate.c does (docs/cpfg.md).
  bool uses_cut = false;
  bool ring = false;          // a cpfg 'ring lsystem': context wraps from the word's end to its start (manual 3.1.1)
  // A cpfg file's L-systems by their labels (`Lsystem: 2`), in file order: the first is the
  // main one (its axiom, derivation length and blocks count), the others sub-L-systems
  // (CPFG manual 7.2). Reading the word, a module ?(label, s) makes L-system `label` the
  // one whose productions, decomposition and homomorphism apply to the modules after it,
  // up to its $ (docs/cpfg.md "Sub-L-systems"); -1 for a label that is no whole number
  // (`Lsystem: plant`), which nothing can call. Empty for sylva's own format.
  std::vector<int64_t> lsystem_labels;
  bool has_sub_lsystems() const { return lsystem_labels.size() > 1; }
  // What each sub-L-system has of its own (CPFG manual 7.2; cpfg keeps them per LSYSDATA): the
  // modules its context passes over (`ignore:`/`consider:`; none unless it says), whether it
  // is a ring, its homomorphism's and its decomposition's maximum depth (1 unless it says).
  // Index k - 1 for the L-system k of lsystem_labels; the main one's are the fields above.
  struct SubLsystem {
    std::vector<uint8_t> ignored;
    bool ring = false;
    int max_depth = 1;
    int decomposition_depth = 1;
  };
  std::vector<SubLsystem> sub_lsystems;
  // The L-system k's own (k = 0: the main one's fields).
  const std::vector<uint8_t>& ignored_in(uint32_t k) const { return k ? sub_lsystems[k - 1].ignored : ignored; }
  bool ring_in(uint32_t k) const { return k ? sub_lsystems[k - 1].ring : ring; }
  // The tables by symbol id sized for `nsym` symbols (the ignore lists: new symbols are not ignored).
  void resize_symbol_tables(size_t nsym) {
    ignored.resize(nsym, 0);
    for (SubLsystem& s : sub_lsystems) s.ignored.resize(nsym, 0);
  }
  // Whether some sub-L-system passes over other modules than the main one, or is a ring.
  bool sub_contexts_differ() const {
    for (const SubLsystem& s : sub_lsystems)
      if (s.ignored != ignored || s.ring != ring) return true;
    return false;
  }

  // The physical source line at `loc` (in its file) without its newline, for messages.
  std::string_view source_line(SourceLoc loc) const;
  // A Diagnostic at `loc` in this grammar's file, or in the included file it names, then
  // with a note at each #include that led there.
  Diagnostic error_at(SourceLoc loc, std::string message) const;
};

// The random stream of the axiom's arguments for a given seed.
inline Rng axiom_rng(uint64_t seed) { return Rng(mix_pair(seed, 0xA710A5EEDULL)); }

struct ParseOptions {
  // -D overrides: replace the value of a #define. A name the grammar does not define
  // is an error (a typo must not be ignored silently).
  std::map<std::string, double> define_overrides;
  // A vlab object's user-defined functions, from its view file's `function:` and `function
  // set:` lines (docs/cpfg.md "Functions"): func(id, x) reads them (Program::functions).
  std::vector<SplineFunction> functions;
  // Its contour functions' curves, from the view file's `curve:` lines: curveX(id, t) ...
  // and curveGAL(id) read them (Program::curves; docs/cpfg.md "Contour functions").
  std::vector<CpfgCurve> curves;
  // Object-like macros defined before a cpfg model is preprocessed, as cpfg passes cpp
  // `-DNAME=id` for each function of a function set; the model may define them again.
  std::vector<std::pair<std::string, std::string>> predefined_macros;
};

// Work done by parse_grammar on this thread, for the tests that hold docs/limits.md's
// "Work" table (reset it before the parse to measure): bytes the logical lines copied as
// they grew (continuations joined), the logical lines kept (blank ones are not), and
// #define names compared looking for a second definition.
struct ParseWork {
  uint64_t line_bytes_copied = 0;
  uint64_t logical_lines = 0;
  uint64_t define_compares = 0;
};
ParseWork& parse_work();

// True if `path` names a grammar by its form: a `.lsys` file, a cpfg model file (`.l`), or a
// folder (a vlab object, vlab_object.h). What every front end takes as a grammar input.
bool is_grammar_path(const std::string& path);

// True if `text` is a cpfg model file (docs/spec/grammar.md): its first line that is not
// blank, a comment or a preprocessor line is `Lsystem: ...`, in any case.
bool is_cpfg_text(std::string_view text);

// Parses and compiles grammar text. `file` names the grammar in messages (and, for a cpfg
// file, its folder is where #include looks).
Expected<Grammar> parse_grammar(std::string_view text, std::string file,
                                const ParseOptions& options = {});

// Reads and parses a grammar file; an unreadable file is an error naming the path. A folder
// is read as a vlab object (vlab_object.h).
Expected<Grammar> load_grammar(const std::string& path, const ParseOptions& options = {});

// Parses a word as `sylva derive` prints it (constant arguments only), with the
// grammar's symbols (declared multi-character names). Used for round-trip checks and
// by tools that read words back.
Expected<Word> parse_word(std::string_view text, Grammar& grammar);

}  // namespace sylva::lsys
