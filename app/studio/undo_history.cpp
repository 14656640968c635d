// undo_history.cpp — see undo_history.h.
#include "app/studio/undo_history.h"

#include <cassert>
#include <utility>

namespace sylva::studio {

UndoHistory::UndoHistory(DocState initial, size_t limit) : limit_(limit < 2 ? 2 : limit) {
  states_.push_back(std::move(initial));
}

bool UndoHistory::record(const DocState& state) {
  if (state == states_[index_]) return false;
  states_.resize(index_ + 1);
  states_.push_back(state);
  if (states_.size() > limit_) states_.erase(states_.begin());
  index_ = states_.size() - 1;
  return true;
}

const DocState& UndoHistory::undo() {
  assert(can_undo());
  return states_[--index_];
}

const DocState& UndoHistory::redo() {
  assert(can_redo());
  return states_[++index_];
}

void UndoHistory::reset(DocState state) {
  states_.clear();
  states_.push_back(std::move(state));
  index_ = 0;
}

}  // namespace sylva::studio
