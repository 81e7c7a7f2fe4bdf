#pragma once
// Real-time pacing for replayed sources: frame k is released at
// start + (k + offset) / fps on CLOCK_REALTIME, so a replayed camera behaves like a live one
// (including its time offset against other replayed cameras that share `start`).

#include <cstdint>

namespace silnet::node {

// Releases frames at their due time.
class FramePacer {
 public:
  // `fps` > 0; `start_ns` is the CLOCK_REALTIME instant of reference time 0; `offset_frames`
  // shifts this camera's frames (frame k is due at reference time (k + offset) / fps).
  FramePacer(double fps, int64_t start_ns, double offset_frames = 0.0);

  // The CLOCK_REALTIME instant at which frame k is due.
  int64_t DueTimeNs(uint64_t frame) const;
  // Sleeps until frame k is due (returns at once if it is late) and returns its due time.
  int64_t WaitFor(uint64_t frame) const;
  // Sleeps until frame k is due or `limit_ns` (CLOCK_REALTIME) passes; true if it is due.
  bool WaitForUntil(uint64_t frame, int64_t limit_ns) const;

 private:
  double fps_;
  int64_t start_ns_;
  double offset_frames_;
};

}  // namespace silnet::node
