// diagnostic.h — the one located error type of sylva, and the result types that carry it
// across every boundary (grammar, skeleton, scene, glTF, textures, images, files).
//
// Every problem a user can cause (bad grammar text, a derivation that divides by zero,
// runaway growth, a skeleton or scene file that breaks its schema, an unreadable texture,
// a file that cannot be written) comes back as a Diagnostic value: the file, a 1-based
// line and column, a message, and — where the reader holds the text — the source line so
// front ends can draw a caret. Notes point at further places that explain the error: a
// grammar error met while growing a scene's plant carries a note at the scene key that
// named the grammar, so an editor can underline both. The CLI prints format(); the
// studio shows the same text and underlines file:line:column of the error and its notes.
//
// Work stopped through a cancellation token (progress.h) is not a failure: it comes back
// as a Diagnostic with `cancelled` set (message "cancelled"), so callers can tell the two
// apart without exceptions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace sylva {

// A place in a text file: 1-based line and column. {0,0} means "no place" (a file that
// cannot be read, an error about the whole file). Columns count bytes in grammar text
// (docs/spec/grammar.md) and code points in JSON files (json.h); the two agree on ASCII lines.
// `file` tells the files of a set apart (a cpfg grammar and the files it #includes:
// lsystem/grammar.h); 0 is the main one, the only one elsewhere.
struct SourceLoc {
  uint32_t line = 0;
  uint32_t column = 0;
  uint32_t file = 0;
  bool operator==(const SourceLoc&) const = default;
};

// One error (or note): "file:line:column: error: message", then the source line and a
// caret when the source line is known, then the notes.
struct Diagnostic {
  std::string file;                        // the file as the user named it; may be empty
  SourceLoc loc;                           // where in `file`; {0,0}: the file as a whole
  std::string message;                     // one sentence, without the place
  std::optional<std::string> source_line;  // the physical line at loc, when the reporter
                                           //   had the text (format() echoes it with a caret);
                                           //   a long line only around loc (set_source_line)
  size_t source_offset = 0;                // bytes of the line left out before source_line
  std::vector<Diagnostic> notes;           // further places that explain this one, in order
  int error_number = 0;                    // errno of the failing system call (file I/O); 0: none
  bool cancelled = false;                  // the work was cancelled, not failed (progress.h)

  // Multi-line text, every line ending in '\n':
  //   FILE:LINE:COLUMN: error: MESSAGE      (":COLUMN" left out when 0, ":LINE:COLUMN" when
  //                                          the line is 0; "FILE: " when the file is empty)
  //   SOURCE LINE                           (only with source_line; long lines clipped
  //   ^ under the column                     around the column, control bytes as '?')
  //   then each note the same way, with "note:" for "error:".
  std::string format() const;

  // This diagnostic with `note` appended to its notes.
  Diagnostic with_note(Diagnostic note) &&;
};

// A Diagnostic at `loc` in `file`, without source line.
Diagnostic diagnostic_at(std::string file, SourceLoc loc, std::string message);

// Sets d.source_line to `line`, the physical line at d.loc — of a line longer than
// kMaxSourceLineBytes only the kMaxSourceLineBytes around d.loc.column (d.source_offset
// the bytes left out before them), so an error in a 1 GiB line does not copy it.
inline constexpr size_t kMaxSourceLineBytes = 4096;
void set_source_line(Diagnostic& d, std::string_view line);

// A Diagnostic for `file` as a whole (no place, no source line).
Diagnostic file_diagnostic(std::string file, std::string message, int error_number = 0);

// The Diagnostic of cancelled work: cancelled = true, message "cancelled".
Diagnostic cancelled_diagnostic();

// The value of an operation that can fail with a Diagnostic (a minimal std::expected).
template <class T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}                // NOLINT: implicit by design
  Expected(Diagnostic error) : v_(std::move(error)) {}       // NOLINT: implicit by design
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  // True when the operation was cancelled (progress.h) rather than failed.
  bool cancelled() const { return !ok() && error().cancelled; }
  T& value() { return std::get<0>(v_); }
  const T& value() const { return std::get<0>(v_); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  Diagnostic& error() { return std::get<1>(v_); }
  const Diagnostic& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Diagnostic> v_;
};

// The result of an operation that returns nothing but can fail: success, or a Diagnostic.
template <>
class [[nodiscard]] Expected<void> {
 public:
  Expected() = default;                                               // success
  Expected(Diagnostic error) : error_(std::move(error)) {}            // NOLINT: implicit by design
  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }
  bool cancelled() const { return !ok() && error_->cancelled; }
  Diagnostic& error() { return *error_; }
  const Diagnostic& error() const { return *error_; }

 private:
  std::optional<Diagnostic> error_;
};

using Status = Expected<void>;

}  // namespace sylva
