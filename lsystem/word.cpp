// word.cpp — symbol table, word storage and word printing (grammar.md "Printing a word").
#include "lsystem/word.h"

#include <algorithm>
#include <cassert>
#include <charconv>

namespace sylva::lsys {

namespace {
constexpr const char* kBuiltinNames[kBuiltinSymbolCount] = {
    "F", "f", "+", "-", "&", "^", "\\", "/", "|", "$", "[", "]", "!", "'", "%", "@T"};

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

void SymbolTable::declare_multichar(std::string_view name) {
  if (std::find(multichar_.begin(), multichar_.end(), name) != multichar_.end()) return;
  multichar_.emplace_back(name);
  if (!name.empty()) multichar_first_byte_[static_cast<unsigned char>(name[0])] = true;
  std::stable_sort(multichar_.begin(), multichar_.end(),
                   [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
}

size_t SymbolTable::match_multichar(std::string_view text) const {
  if (text.empty() || !multichar_first_byte_[static_cast<unsigned char>(text[0])]) return 0;
  for (const std::string& name : multichar_)
    if (text.substr(0, name.size()) == name) return name.size();
  return 0;
}

bool SymbolTable::has_longer_multichar(std::string_view name) const {
  for (const std::string& m : multichar_)
    if (m.size() > name.size() && std::string_view(m).substr(0, name.size()) == name) return true;
  return false;
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
      // Would the reader take a longer name here? Look ahead over the next names.
      std::string ahead = name;
      for (size_t j = i + 1; j < n && ahead.size() < name.size() + 64; ++j) {
        ahead += symbols.name(word.modules[j].symbol);
        if (word.modules[j].param_count) break;
      }
      if (symbols.module_name_length(ahead) != name.size()) out += ' ';
    }
  }
  return out;
}

}  // namespace sylva::lsys
