// fuzz_check.h — how a fuzz target reports a broken property (not a crash the sanitizers
// see, but a promise of a reader's header that an input broke): the target's name, what
// broke and the detail on stderr, then abort(), which libFuzzer records as a crash with
// its input (docs/fuzzing.md).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/util/diagnostic.h"

namespace sylva::fuzz {

[[noreturn]] inline void fail(const char* target, const char* what, const std::string& detail) {
  std::fprintf(stderr, "%s: %s\n%s\n", target, what, detail.c_str());
  std::abort();
}

// A reader's error must name the file it was given and say something; formatting it (the
// caret line under the column) must not fail either.
inline void check_error(const char* target, const Diagnostic& d, const std::string& file) {
  const std::string text = d.format();
  if (d.file != file || d.message.empty()) fail(target, "an error without its file or message", text);
}

}  // namespace sylva::fuzz
