// diagnostic.h — located error messages for grammar text, and the result type that
// carries them across the lsystem boundary.
//
// Every problem a user can cause (bad grammar text, a derivation that divides by zero,
// runaway growth) comes back as a Diagnostic value: file, 1-based line and column (in
// bytes), a message, and the source line so front ends can draw a caret. The CLI prints
// format(); the GUI shows the same text at the same place.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <variant>

namespace sylva {

// A place in a grammar file: 1-based line and column (bytes). {0,0} means "no place".
struct SourceLoc {
  uint32_t line = 0;
  uint32_t column = 0;
};

// One error: "file:line:column: error: message", then the source line and a caret.
struct Diagnostic {
  std::string file;
  SourceLoc loc;
  std::string message;
  std::string source_line;  // the physical line at loc (empty when loc is {0,0})

  // Multi-line text: the located first line, then the source line and a caret line.
  std::string format() const;
};

// The value of an operation that can fail with a Diagnostic (a minimal std::expected).
template <class T>
class Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}                // NOLINT: implicit by design
  Expected(Diagnostic error) : v_(std::move(error)) {}       // NOLINT: implicit by design
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() { return std::get<0>(v_); }
  const T& value() const { return std::get<0>(v_); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  const Diagnostic& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Diagnostic> v_;
};

}  // namespace sylva
