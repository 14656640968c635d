// lsystem_test_util.h — helpers shared by the lsystem tests: grammar text in, word out.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sylva::lsys::testing {

// Parses `text`; fails the test with the diagnostic if it does not parse.
inline Grammar parse_ok(const std::string& text, const ParseOptions& options = {}) {
  auto g = parse_grammar(text, "test.lsys", options);
  EXPECT_TRUE(g.ok()) << (g.ok() ? "" : g.error().format());
  if (!g.ok()) return Grammar{};
  return std::move(*g);
}

// The diagnostic of text that must not parse.
inline Diagnostic parse_error(const std::string& text, const ParseOptions& options = {}) {
  auto g = parse_grammar(text, "test.lsys", options);
  EXPECT_FALSE(g.ok()) << "parsed, but an error was expected";
  if (g.ok()) return Diagnostic{};
  return g.error();
}

// Derive options for `n` steps.
inline DeriveOptions steps(int64_t n) {
  DeriveOptions o;
  o.steps = n;
  return o;
}

// Derives `text` and prints the word ("<error: ...>" on failure).
inline std::string derive_text(const std::string& text, DeriveOptions options = {}) {
  auto g = parse_grammar(text, "test.lsys");
  if (!g.ok()) return "<parse error: " + g.error().format() + ">";
  auto w = derive(*g, options);
  if (!w.ok()) return "<error: " + w.error().message + ">";
  return print_word(*w, g->symbols);
}

}  // namespace sylva::lsys::testing
