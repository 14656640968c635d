// diagnostic.cpp — formatting of located errors (clang style: message, line, caret).
#include "lsystem/diagnostic.h"

namespace sylva::lsys {

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
    for (char& c : shown)
      if (c == '\t') c = ' ';
    out += prefix + shown + (begin + kWindow < source_line.size() ? "..." : "") + "\n";
    out += std::string(prefix.size() + (col - begin), ' ') + "^\n";
  }
  return out;
}

}  // namespace sylva::lsys
