// diagnostic.cpp — formatting of located errors (clang style: message, line, caret).
#include "core/util/diagnostic.h"

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
}  // namespace

std::string Diagnostic::format() const {
  std::string out = file;
  if (loc.line) out += ":" + std::to_string(loc.line) + ":" + std::to_string(loc.column);
  out += ": error: " + message + "\n";
  if (loc.line) {
    // Long lines (a 10 MB axiom) are shown around the column only.
    constexpr size_t kWindow = 160;
    size_t col = loc.column ? loc.column - 1 : 0;
    size_t begin = col > kWindow / 2 ? col - kWindow / 2 : 0;
    std::string shown = source_line.substr(begin, kWindow);
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
    out += std::string(prefix.size() + (col - begin), ' ') + "^\n";
  }
  return out;
}

}  // namespace sylva
