// word.cpp — symbol table, word storage and word printing (docs/spec/grammar.md "Printing a word").
#include "lsystem/word.h"

#include <algorithm>
#include <cassert>
#include <charconv>

namespace sylva::lsys {

namespace {
constexpr const char* kBuiltinNames[kBuiltinSymbolCount] = {
    "F", "f", "+", "-", "&", "^", "\\", "/", "|", "$", "[", "]", "!", "'", "%", "@T", "@Tp", "?E", "?P", "?H", "?L", "?U"};

// Bytes in the UTF-8 sequence that starts with `lead` (1 for anything malformed; the
// parser validates UTF-8 before tokenising).
size_t utf8_length(unsigned char lead) {
  if (lead < 0x80) return 1;
  if ((lead >> 5) == 0x6) return 2;
  if ((lead >> 4) == 0xE) return 3;
  if ((lead >> 3) == 0x1E) return 4;
  return 1;
}
}  // namespace

SymbolTable::SymbolTable() {
  std::fill(std::begin(ascii_ids_), std::end(ascii_ids_), -1);
  for (const char* name : kBuiltinNames) intern(name);
  declare_multichar("@T");
  declare_multichar("@Tp");
  for (const char* query : {"?E", "?P", "?H", "?L", "?U"}) declare_multichar(query);
}

SymbolId SymbolTable::intern(std::string_view name, bool* ok) {
  const bool ascii = name.size() == 1 && static_cast<unsigned char>(name[0]) < 128;
  if (ascii && ascii_ids_[static_cast<unsigned char>(name[0])] >= 0) {
    if (ok) *ok = true;
    return static_cast<SymbolId>(ascii_ids_[static_cast<unsigned char>(name[0])]);
  }
  auto it = ids_.find(std::string(name));
  if (it != ids_.end()) {
    if (ok) *ok = true;
    return it->second;
  }
  if (names_.size() >= 65535) {
    if (ok) *ok = false;
    return 0;
  }
  SymbolId id = static_cast<SymbolId>(names_.size());
  names_.emplace_back(name);
  ids_.emplace(std::string(name), id);
  if (ascii) ascii_ids_[static_cast<unsigned char>(name[0])] = id;
  if (ok) *ok = true;
  return id;
}

bool SymbolTable::find(std::string_view name, SymbolId* id) const {
  auto it = ids_.find(std::string(name));
  if (it == ids_.end()) return false;
  *id = it->second;
  return true;
}

SymbolWork& symbol_work() {
  thread_local SymbolWork work;
  return work;
}

namespace {
constexpr uint32_t kNoNode = 0xFFFFFFFFu;
uint64_t edge_key(uint32_t node, unsigned char byte) { return (uint64_t{node} << 8) | byte; }
}  // namespace

uint32_t SymbolTable::trie_child(uint32_t node, unsigned char byte) const {
  ++symbol_work().trie_steps;
  auto it = trie_edges_.find(edge_key(node, byte));
  return it == trie_edges_.end() ? kNoNode : it->second;
}

void SymbolTable::declare_multichar(std::string_view name) {
  if (name.empty()) return;
  multichar_first_byte_[static_cast<unsigned char>(name[0])] = true;
  uint32_t node = 0;
  for (char ch : name) {
    const unsigned char byte = static_cast<unsigned char>(ch);
    uint32_t child = trie_child(node, byte);
    if (child == kNoNode) {
      child = static_cast<uint32_t>(trie_terminal_.size());
      trie_terminal_.push_back(0);
      trie_has_child_.push_back(0);
      trie_edges_.emplace(edge_key(node, byte), child);
      trie_has_child_[node] = 1;
    }
    node = child;
  }
  trie_terminal_[node] = 1;
}

size_t SymbolTable::match_multichar(std::string_view text) const {
  if (text.empty() || !multichar_first_byte_[static_cast<unsigned char>(text[0])]) return 0;
  // The deepest terminal node on text's path is the longest declared name it starts with.
  size_t longest = 0;
  uint32_t node = 0;
  for (size_t i = 0; i < text.size() && trie_has_child_[node]; ++i) {
    node = trie_child(node, static_cast<unsigned char>(text[i]));
    if (node == kNoNode) break;
    if (trie_terminal_[node]) longest = i + 1;
  }
  return longest;
}

bool SymbolTable::walk_multichar(uint32_t* node, size_t* depth, size_t* longest, std::string_view piece) const {
  for (char ch : piece) {
    if (!trie_has_child_[*node]) return false;
    *node = trie_child(*node, static_cast<unsigned char>(ch));
    if (*node == kNoNode) return false;
    ++*depth;
    if (trie_terminal_[*node]) *longest = *depth;
  }
  return trie_has_child_[*node] != 0;
}

bool SymbolTable::has_longer_multichar(std::string_view name) const {
  uint32_t node = 0;
  for (char ch : name) {
    node = trie_child(node, static_cast<unsigned char>(ch));
    if (node == kNoNode) return false;
  }
  return trie_has_child_[node] != 0;
}

size_t SymbolTable::module_name_length(std::string_view text) const {
  assert(!text.empty());
  size_t n = match_multichar(text);
  if (n) return n;
  return std::min(text.size(), utf8_length(static_cast<unsigned char>(text[0])));
}

size_t Word::capacity_bytes() const {
  return modules.capacity() * sizeof(Module) + params.capacity() * sizeof(double) +
         lineage.capacity() * sizeof(uint64_t);
}

void Word::clear() {
  modules.clear();
  params.clear();
  lineage.clear();
}

void append_shortest_double(std::string& out, double value) {
  char buf[32];
  auto result = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, result.ptr);
}

std::string print_word(const Word& word, const SymbolTable& symbols) {
  // A space is needed after a module without parameters only if its name is a proper
  // prefix of some declared multi-character name (else no reader could merge it).
  std::vector<uint8_t> may_merge(symbols.size(), 0);
  for (size_t id = 0; id < symbols.size(); ++id) {
    const std::string& name = symbols.name(static_cast<SymbolId>(id));
    may_merge[id] = symbols.has_longer_multichar(name);
  }
  std::string out;
  out.reserve(word.size() * 2);
  const size_t n = word.size();
  for (size_t i = 0; i < n; ++i) {
    const Module& m = word.modules[i];
    const std::string& name = symbols.name(m.symbol);
    out += name;
    if (m.param_count) {
      out += '(';
      const double* p = word.params_of(m);
      for (uint16_t k = 0; k < m.param_count; ++k) {
        if (k) out += ',';
        append_shortest_double(out, p[k]);
      }
      out += ')';
    } else if (i + 1 < n && may_merge[m.symbol]) {
      // Would the reader take a longer name here? Walk the name trie over the next names
      // for as long as some declared name continues them.
      uint32_t node = 0;
      size_t depth = 0, longest = 0;
      bool more = symbols.walk_multichar(&node, &depth, &longest, name);
      for (size_t j = i + 1; more && j < n; ++j) {
        more = symbols.walk_multichar(&node, &depth, &longest, symbols.name(word.modules[j].symbol));
        if (word.modules[j].param_count) break;
      }
      if (longest > name.size()) out += ' ';
    }
  }
  return out;
}

}  // namespace sylva::lsys
