// word.h — symbols and words: the data an L-system derivation works on.
//
// A word is a flat array of compact module records (symbol id, parameter count, offset
// into one shared parameter array), never strings or per-module heap objects: a module
// without parameters costs 8 bytes. Lineage keys (for stable random streams) are stored
// only when the grammar draws random numbers.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace sylva::lsys {

using SymbolId = uint16_t;

// Symbols the turtle and the derivation give a meaning to. Every SymbolTable registers
// them first, in this order, so their ids are these constants in every grammar.
enum BuiltinSymbol : SymbolId {
  kSymF = 0,        // F   move and draw
  kSymf,            // f   move without drawing
  kSymTurnLeft,     // +   rotate about U, H toward L
  kSymTurnRight,    // -
  kSymPitchDown,    // &   rotate about L, H toward -U
  kSymPitchUp,      // ^
  kSymRollLeft,     // \   rotate about H, U toward L
  kSymRollRight,    // /
  kSymTurnAround,   // |
  kSymLevel,        // $
  kSymPush,         // [
  kSymPop,          // ]
  kSymWidth,        // !
  kSymMaterial,     // '
  kSymCut,          // %
  kSymTropism,      // @T
  kSymTropismVector,// @Tp  set the tropism vector (light.md)
  kSymLightQuery,   // ?E   a light query, answered after every step (light.md)
  kSymQueryPosition,// ?P   the turtle's position, filled after every step (CPFG manual 6.9)
  kSymQueryHeading, // ?H   its heading
  kSymQueryLeft,    // ?L   its left vector
  kSymQueryUp,      // ?U   its up vector
  kBuiltinSymbolCount
};

// ?P, ?H, ?L or ?U: a query the turtle answers (CPFG manual 6.9).
inline bool is_turtle_query(SymbolId s) { return s >= kSymQueryPosition && s <= kSymQueryUp; }

// Work done by the symbol table's multi-character name lookups on this thread: one unit
// per byte walked in the name trie. Exposed so tests can assert that declaring, tokenising
// and printing stay linear (docs/limits.md "Work"); reset it before the work to measure.
struct SymbolWork {
  uint64_t trie_steps = 0;
};
SymbolWork& symbol_work();

// Module names <-> ids. Names are one UTF-8 character unless declared with `module:`
// (or the built-in @T); tokenisation takes the longest declared name at each place.
// Declared names live in a byte trie, so declaring a name, matching the longest name at a
// place and asking whether a longer name extends one each cost the name's length, however
// many names are declared.
class SymbolTable {
 public:
  SymbolTable();
  // Id of `name`, registering it if new. Returns false in `ok` past 65535 symbols.
  SymbolId intern(std::string_view name, bool* ok = nullptr);
  // Id of `name` if it is known.
  bool find(std::string_view name, SymbolId* id) const;
  const std::string& name(SymbolId id) const { return names_[id]; }
  size_t size() const { return names_.size(); }
  // Declares a multi-character name for longest-match tokenisation.
  void declare_multichar(std::string_view name);
  // Length in bytes of the longest declared multi-character name that `text` starts
  // with, or 0 when none does.
  size_t match_multichar(std::string_view text) const;
  // True if some declared multi-character name is longer than `name` and starts with it.
  bool has_longer_multichar(std::string_view name) const;
  // Continues a walk down the name trie by `piece`, for a text given in pieces (the names
  // of following modules). Start with *node = 0 and *depth = 0; *longest becomes the
  // length of the longest declared name the whole text so far starts with (unchanged when
  // none is longer). Returns false once no declared name continues the text.
  bool walk_multichar(uint32_t* node, size_t* depth, size_t* longest, std::string_view piece) const;
  // Length in bytes of the module name that `text` starts with: the longest declared
  // multi-character name, else one UTF-8 character. Precondition: text not empty.
  size_t module_name_length(std::string_view text) const;

 private:
  std::vector<std::string> names_;
  std::unordered_map<std::string, SymbolId> ids_;
  // The trie of declared multi-character names: node 0 is the root; an edge is keyed by
  // (parent node << 8 | byte).
  uint32_t trie_child(uint32_t node, unsigned char byte) const;
  std::unordered_map<uint64_t, uint32_t> trie_edges_;
  std::vector<uint8_t> trie_terminal_ = {0};   // by node: a declared name ends here
  std::vector<uint8_t> trie_has_child_ = {0};  // by node: some longer name continues it
  int32_t ascii_ids_[128];               // id of each one-byte name, or -1: the fast path
  bool multichar_first_byte_[256] = {};  // bytes that start some multi-character name
};

// One module of a word: 8 bytes.
struct Module {
  SymbolId symbol;
  uint16_t param_count;
  uint32_t param_begin;  // index of the first parameter in Word::params
};

struct Word {
  std::vector<Module> modules;
  std::vector<double> params;
  // Lineage key of each module (parallel to modules), or empty when the grammar draws
  // no random numbers. See derive.cpp for how keys are made.
  std::vector<uint64_t> lineage;
  // A cpfg file's global variables (Grammar::global_names) after the derivation that made
  // this word: interpret() reads them. Empty without globals.
  std::vector<double> globals;

  size_t size() const { return modules.size(); }
  const double* params_of(const Module& m) const { return params.data() + m.param_begin; }
  // Bytes held by the arrays (capacity, not size): what a word really costs.
  size_t capacity_bytes() const;
  void clear();
};

// Prints a word as docs/spec/grammar.md "Printing a word" says: modules without separators,
// arguments in shortest round-trip decimal, a space after a module only where the next
// module would otherwise merge with it when read back.
// Its cost is the word's length times at most the longest declared name (the look-ahead
// after a name that a longer one extends), whatever the number of names.
std::string print_word(const Word& word, const SymbolTable& symbols);

// Appends the shortest decimal text that reads back as exactly `value`.
void append_shortest_double(std::string& out, double value);

}  // namespace sylva::lsys
