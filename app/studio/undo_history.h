// undo_history.h — the studio's document-level undo (docs/spec/studio.md "Editor"): whole
// snapshots of what the user edits — the grammar text and the parameter panel's
// overrides — never the editor widget's keystroke history, so one slider drag or one
// burst of typing is one step, and decorations (error marks) never enter the history
// (the lesson of L-Py's editor, whose error highlight leaks into its undo stack).
//
// When a snapshot is taken is the caller's business (the studio: after a pause in
// typing, on leaving the editor, when a slider is released). record() ignores a
// snapshot equal to the current one, so taking one "just in case" costs nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace sylva::studio {

// Everything one undo step restores.
struct DocState {
  std::string text;                        // the grammar text
  std::map<std::string, double> defines;   // parameter overrides (not in the text)
  std::optional<uint64_t> seed;            // seed override
  std::optional<int64_t> steps;            // derivation-steps override
  bool operator==(const DocState&) const = default;
};

class UndoHistory {
 public:
  explicit UndoHistory(DocState initial = {}, size_t limit = 1000);

  // Makes `state` the newest step (dropping any redo steps) unless it equals the
  // current one. Returns whether a step was added. Past `limit` steps the oldest go.
  bool record(const DocState& state);

  bool can_undo() const { return index_ > 0; }
  bool can_redo() const { return index_ + 1 < states_.size(); }
  // Move one step back / forward and return the state there. Preconditions:
  // can_undo() / can_redo().
  const DocState& undo();
  const DocState& redo();

  const DocState& current() const { return states_[index_]; }
  size_t size() const { return states_.size(); }
  // Forgets every step; `state` becomes the only one (a newly opened document).
  void reset(DocState state);

 private:
  std::vector<DocState> states_;
  size_t index_ = 0;
  size_t limit_;
};

}  // namespace sylva::studio
