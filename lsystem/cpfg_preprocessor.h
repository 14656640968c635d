// cpfg_preprocessor.h — the C preprocessor that cpfg runs over a model file before reading
// it (docs/spec/grammar.md "cpfg model files and vlab objects", docs/cpfg.md). Internal to
// lsystem/: the parser calls it for a text that is_cpfg_text().
//
// What it does, as cpp does: removes `/* */` and `//` comments (not inside "strings"), joins
// lines that end in `\`, obeys `#define` (object- and function-like), `#undef`, `#include
// "file"`, `#if`/`#ifdef`/`#ifndef`/`#elif`/`#else`/`#endif`, `#error` and `#pragma` (read
// and ignored), and expands macros in every other line (a macro is not expanded inside its
// own expansion). What it adds for sylva:
// - every byte of the result remembers its place: the file (Grammar::includes), line and
//   column it came from, or for a macro's expansion the place of the macro's name;
// - `#include` resolves only inside the main file's folder (no absolute path, no escape by
//   `..` or a link), at most 16 deep, never recursively;
// - an object-like define whose value is one number is a Define (grammar.h): `-D NAME=v`
//   replaces its value, and the studio makes it a slider;
// - bounded work: a line's expansion at most 1 MiB, macros at most 256 deep.
// Errors are thrown as detail::ParseFailure at their place.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "lsystem/grammar.h"
#include "lsystem/source_text.h"

namespace sylva::lsys::detail {

struct CpfgSource {
  std::vector<LogicalLine> lines;  // the model's lines after the preprocessor, none blank
  std::vector<Define> defines;     // object-like defines whose value is a number
};

// Preprocesses the cpfg model `text`, read from `file` (its folder is where #include looks).
// Each file #include reads is appended to `includes` as it is read (file index k + 1), so an
// error thrown inside one can be shown at its place.
CpfgSource preprocess_cpfg(std::string_view text, const std::string& file, const ParseOptions& options,
                           std::vector<IncludedFile>& includes);

}  // namespace sylva::lsys::detail
