#include "node/capture/frame_pacer.h"

#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>

#include "node/capture/capture_source.h"
#include "shared/util/check.h"

namespace silnet::node {
namespace {

void SleepUntilRealtime(int64_t when_ns) {
  timespec target{};
  target.tv_sec = static_cast<time_t>(when_ns / 1000000000LL);
  target.tv_nsec = static_cast<long>(when_ns % 1000000000LL);
  // Absolute sleeps resume after a signal; any other error ends the wait.
  while (clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &target, nullptr) == EINTR) {
  }
}

}  // namespace

FramePacer::FramePacer(double fps, int64_t start_ns, double offset_frames)
    : fps_(fps), start_ns_(start_ns), offset_frames_(offset_frames) {
  SILNET_CHECK_MSG(fps > 0.0, "pacing needs a positive frame rate");
}

int64_t FramePacer::DueTimeNs(uint64_t frame) const {
  const double seconds = (static_cast<double>(frame) + offset_frames_) / fps_;
  return start_ns_ + static_cast<int64_t>(std::llround(seconds * 1e9));
}

int64_t FramePacer::WaitFor(uint64_t frame) const {
  const int64_t due = DueTimeNs(frame);
  if (due > RealtimeNowNs()) SleepUntilRealtime(due);
  return due;
}

bool FramePacer::WaitForUntil(uint64_t frame, int64_t limit_ns) const {
  const int64_t due = DueTimeNs(frame);
  const int64_t now = RealtimeNowNs();
  if (due <= now) return true;
  SleepUntilRealtime(std::min(due, limit_ns));
  return due <= limit_ns;
}

}  // namespace silnet::node
