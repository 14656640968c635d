// diagnostic.cpp — formatting of located errors (clang style: message, line, caret, notes).
#include "core/util/diagnostic.h"

#include <algorithm>

namespace sylva {

namespace {
// Structural UTF-8 check (lead and continuation bytes), enough to decide how to echo.
bool valid_utf8(const std::string& s) {
  for (size_t i = 0; i < s.size();) {
    unsigned char c = static_cast<unsigned char>(s[i]);
    size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (len == 0 || i + len > s.size()) return false;
    for (size_t k = 1; k < len; ++k)
      if ((static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) return false;
    i += len;
  }
  return true;
}

// The source line and a caret under `column` (1-based bytes).
void append_excerpt(std::string& out, const std::string& source_line, uint32_t column) {
  // Long lines (a 10 MB axiom) are shown around the column only.
  constexpr size_t kWindow = 160;
  size_t col = column ? column - 1 : 0;
  size_t begin = col > kWindow / 2 ? col - kWindow / 2 : 0;
  std::string shown = source_line.substr(std::min(begin, source_line.size()), kWindow);
  std::string prefix = begin ? "..." : "";
  // Echo the line safely: control bytes (and, in a line that is not valid UTF-8, every
  // non-ASCII byte) become '?', one byte for one byte so the caret stays aligned.
  const bool utf8 = valid_utf8(shown);
  for (char& c : shown) {
    unsigned char b = static_cast<unsigned char>(c);
    if (c == '\t') c = ' ';
    else if (b < 0x20 || b == 0x7f || (!utf8 && b >= 0x80)) c = '?';
  }
  out += prefix + shown + (begin + kWindow < source_line.size() ? "..." : "") + "\n";
  // The caret under the character: one space per character before it, not per byte (the
  // column in the header counts bytes, as clang's does; issue 32 found "é" pushing the
  // caret off). A line that is not UTF-8 is echoed a byte per '?', so bytes are characters.
  size_t before = 0;
  for (size_t i = 0; i < std::min(col - begin, shown.size()); ++i)
    before += (static_cast<unsigned char>(shown[i]) >> 6) != 0x2;
  before += col - begin > shown.size() ? col - begin - shown.size() : 0;
  out += std::string(prefix.size() + before, ' ') + "^\n";
}

void append_formatted(std::string& out, const Diagnostic& d, const char* severity) {
  std::string place = d.file;
  if (d.loc.line) {
    if (!place.empty()) place += ':';
    place += std::to_string(d.loc.line);
    if (d.loc.column) place += ":" + std::to_string(d.loc.column);
  }
  if (!place.empty()) out += place + ": ";
  out += std::string(severity) + ": " + d.message + "\n";
  if (d.source_line) {
    const size_t column = d.loc.column > d.source_offset ? d.loc.column - d.source_offset : 0;
    append_excerpt(out, *d.source_line, static_cast<uint32_t>(column));
  }
  for (const Diagnostic& note : d.notes) append_formatted(out, note, "note");
}
}  // namespace

std::string Diagnostic::format() const {
  std::string out;
  append_formatted(out, *this, "error");
  return out;
}

Diagnostic Diagnostic::with_note(Diagnostic note) && {
  notes.push_back(std::move(note));
  return std::move(*this);
}

void set_source_line(Diagnostic& d, std::string_view line) {
  size_t begin = 0;
  if (line.size() > kMaxSourceLineBytes) {
    const size_t column = d.loc.column ? d.loc.column - 1 : 0;
    begin = std::min(column > kMaxSourceLineBytes / 2 ? column - kMaxSourceLineBytes / 2 : 0,
                     line.size() - kMaxSourceLineBytes);
    // Not inside a UTF-8 sequence: back to its lead byte.
    while (begin > 0 && (static_cast<unsigned char>(line[begin]) >> 6) == 0x2) --begin;
  }
  d.source_line = std::string(line.substr(begin, kMaxSourceLineBytes));
  d.source_offset = begin;
}

Diagnostic diagnostic_at(std::string file, SourceLoc loc, std::string message) {
  Diagnostic d;
  d.file = std::move(file);
  d.loc = loc;
  d.message = std::move(message);
  return d;
}

Diagnostic file_diagnostic(std::string file, std::string message, int error_number) {
  Diagnostic d;
  d.file = std::move(file);
  d.message = std::move(message);
  d.error_number = error_number;
  return d;
}

Diagnostic cancelled_diagnostic() {
  Diagnostic d;
  d.message = "cancelled";
  d.cancelled = true;
  return d;
}

}  // namespace sylva
