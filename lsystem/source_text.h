// source_text.h — lsystem's internal view of grammar text, shared by the .lsys parser and the
// cpfg preprocessor (cpfg.h): logical lines that remember where each byte came from, and
// the parse failure both throw. Not part of the library's interface.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/diagnostic.h"

namespace sylva::lsys::detail {

struct ParseFailure {
  SourceLoc loc;
  std::string message;
};

[[noreturn]] inline void fail(SourceLoc loc, std::string message) {
  throw ParseFailure{loc, std::move(message)};
}

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
inline bool is_ident_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
inline bool is_digit(char c) { return c >= '0' && c <= '9'; }
inline bool is_ident_char(char c) { return is_ident_start(c) || is_digit(c); }

// `s` with ASCII capitals made small (cpfg's words are read in any case).
inline std::string lower_ascii(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

// Calls f(line_number, line, last) for each physical line of `text`: 1-based, without its
// newline or CR; `last` when no newline follows it.
template <class F>
void for_each_physical_line(std::string_view text, F&& f) {
  size_t pos = 0;
  uint32_t line_no = 0;
  while (pos <= text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view line = text.substr(pos, nl - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    f(++line_no, line, nl == text.size());
    pos = nl + 1;
  }
}

// One logical line (continuations joined; in a cpfg file, macros expanded) and where its
// bytes come from: one piece per stretch copied from one place (12 bytes of place per
// physical line, not a place per byte: issue 32's 128 MB of blank lines).
struct LogicalLine {
  struct Piece {
    size_t offset = 0;  // text[offset, next piece's offset) is from ...
    uint32_t line = 0;  // ... this physical line, from this column on, ...
    uint32_t column = 1;
    uint32_t file = 0;  // ... of this file (Grammar::includes; 0: the grammar's own)
  };
  std::string text;
  std::vector<Piece> pieces;  // by offset; at least one
  // A cpfg model's line that begins with a tab right after a line that is not blank: cpfg's
  // reader takes a newline followed by a tab as a space (cpfg/lsys_input.l), so the line goes
  // on the one before it (docs/cpfg.md).
  bool continues_previous = false;

  // The source place of text[p]; text.size() (or more): the place just past the end.
  SourceLoc loc(size_t p) const {
    p = std::min(p, text.size());
    auto after = std::upper_bound(pieces.begin(), pieces.end(), p,
                                  [](size_t v, const Piece& piece) { return v < piece.offset; });
    const Piece& piece = *(after - 1);
    return {piece.line, static_cast<uint32_t>(piece.column + (p - piece.offset)), piece.file};
  }
};

// Checks UTF-8, NUL bytes and lone carriage returns; throws at the first problem (in `file`).
void validate_text(std::string_view text, uint32_t file = 0);

}  // namespace sylva::lsys::detail
