// gl_pass_timers.cpp — see gl_pass_timers.h.
#include "core/gl/gl_pass_timers.h"

#include <utility>

#include "core/gl/gl_api.h"

namespace sylva {

void GlPassTimers::begin_frame(uint64_t frame) {
  Slot& slot = slots_[next_];
  next_ = (next_ + 1) % kFramesInFlight;
  if (slot.pending) waited_.push_back(collect(slot));
  slot.frame = frame;
  slot.pending = true;
  slot.used.fill(0);
  recording_ = &slot;
}

void GlPassTimers::begin(GlPass pass) {
  const size_t p = static_cast<size_t>(pass);
  std::vector<GlQuery>& queries = recording_->queries[p];
  if (recording_->used[p] == queries.size()) queries.push_back(make_gl_query(GL_TIME_ELAPSED));
  glBeginQuery(GL_TIME_ELAPSED, queries[recording_->used[p]++].id());
}

void GlPassTimers::end() { glEndQuery(GL_TIME_ELAPSED); }

void GlPassTimers::end_frame() { recording_ = nullptr; }

bool GlPassTimers::ready(const Slot& slot) const {
  for (size_t p = 0; p < kGlPassCount; ++p)
    for (size_t i = 0; i < slot.used[p]; ++i) {
      GLuint available = GL_FALSE;
      glGetQueryObjectuiv(slot.queries[p][i].id(), GL_QUERY_RESULT_AVAILABLE, &available);
      if (!available) return false;
    }
  return true;
}

GlPassTimers::FrameTimes GlPassTimers::collect(Slot& slot) {
  FrameTimes times;
  times.frame = slot.frame;
  for (size_t p = 0; p < kGlPassCount; ++p) {
    uint64_t total_ns = 0;
    for (size_t i = 0; i < slot.used[p]; ++i) {
      GLuint64 ns = 0;
      glGetQueryObjectui64v(slot.queries[p][i].id(), GL_QUERY_RESULT, &ns);
      total_ns += ns;
    }
    times.seconds[p] = static_cast<double>(total_ns) * 1e-9;
  }
  slot.pending = false;
  return times;
}

std::vector<GlPassTimers::FrameTimes> GlPassTimers::collect_ready() {
  std::vector<FrameTimes> out = std::exchange(waited_, {});
  // Oldest first: the slots after the next one to record into, round the ring.
  for (size_t k = 0; k < kFramesInFlight; ++k) {
    Slot& slot = slots_[(next_ + k) % kFramesInFlight];
    if (!slot.pending || &slot == recording_) continue;
    if (!ready(slot)) break;  // later frames finish later
    out.push_back(collect(slot));
  }
  return out;
}

std::vector<GlPassTimers::FrameTimes> GlPassTimers::collect_all() {
  std::vector<FrameTimes> out = std::exchange(waited_, {});
  for (size_t k = 0; k < kFramesInFlight; ++k) {
    Slot& slot = slots_[(next_ + k) % kFramesInFlight];
    if (slot.pending && &slot != recording_) out.push_back(collect(slot));
  }
  return out;
}

}  // namespace sylva
