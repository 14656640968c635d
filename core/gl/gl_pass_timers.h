// gl_pass_timers.h — GPU time per pass (gl_frame_stats.h's GlPass) through GL_TIME_ELAPSED
// queries, read back without stalling the pipeline: a ring of kFramesInFlight frames, each
// with its own query objects (reused frame after frame), whose results are collected once
// the GPU has answered every query of the frame — a frame or more after it was drawn.
//
// Within a frame, each run of a pass is one query (GL allows one GL_TIME_ELAPSED query
// active at a time: runs never nest); a pass's time is the sum over its runs. When the ring
// is full (the GPU kFramesInFlight frames behind), beginning a frame first waits for the
// oldest one's results, so no frame's times are lost.
//
// Preconditions: the GL context current on the calling thread is the one the timers were
// made on, from construction to destruction.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/gl/gl_frame_stats.h"
#include "core/gl/gl_objects.h"

namespace sylva {

class GlPassTimers {
 public:
  static constexpr size_t kFramesInFlight = 4;

  struct FrameTimes {
    uint64_t frame = 0;
    std::array<double, kGlPassCount> seconds{};  // by GlPass
  };

  // Starts recording frame `frame` (a frame whose results had to be waited for to free its
  // slot goes to the next collect).
  void begin_frame(uint64_t frame);
  void begin(GlPass pass);  // one run of `pass`: until end()
  void end();
  void end_frame();

  // The frames whose every query has answered, oldest first, taken out of the ring. Never
  // waits.
  std::vector<FrameTimes> collect_ready();
  // Every recorded frame's times, oldest first, waiting for the GPU as needed.
  std::vector<FrameTimes> collect_all();

 private:
  struct Slot {
    uint64_t frame = 0;
    bool pending = false;  // recorded, results not collected
    std::array<std::vector<GlQuery>, kGlPassCount> queries;  // reused frame after frame
    std::array<size_t, kGlPassCount> used{};                  // queries of this frame
  };
  bool ready(const Slot& slot) const;
  FrameTimes collect(Slot& slot);  // waits where a result is not in yet

  std::array<Slot, kFramesInFlight> slots_;
  std::vector<FrameTimes> waited_;  // collected by begin_frame, not yet handed out
  size_t next_ = 0;          // the slot the next frame records into
  Slot* recording_ = nullptr;
};

}  // namespace sylva
