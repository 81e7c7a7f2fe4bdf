#include "node/capture/files/replayed_frame.h"

#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "shared/util/check.h"
#include "shared/util/realtime_clock.h"

namespace silnet::node {

void CheckReplayOptions(const ReplayOptions& options, const std::string& source) {
  if (options.width < 0 || options.height < 0 || (options.width == 0) != (options.height == 0))
    throw CaptureError(fmt::format("{}: give both width and height, or neither", source));
  if (!std::isfinite(options.fps) || options.fps < 0.0)
    throw CaptureError(fmt::format("{}: bad frame rate {}", source, options.fps));
}

CaptureStatus DeliverReplayedFrame(std::optional<ReplayedFrame>* pending,
                                   const std::optional<FramePacer>& pacer, bool real_time,
                                   uint64_t first_frame, std::chrono::milliseconds timeout,
                                   CapturedFrame* frame, CaptureCounters* counters,
                                   std::string* last_error) {
  SILNET_CHECK(pending->has_value());
  SILNET_CHECK(!real_time || pacer.has_value());
  const uint64_t position = (*pending)->position;
  if (real_time) {
    const int64_t limit =
        RealtimeNowNs() + std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    if (!pacer->WaitForUntil(position, limit)) return CaptureStatus::kTimeout;
  }
  ReplayedFrame released = std::move(**pending);
  pending->reset();
  frame->frame_index = first_frame + position;
  frame->capture_time_ns = pacer ? pacer->DueTimeNs(position) : RealtimeNowNs();
  if (!released.error.empty()) {
    frame->image = cv::Mat();
    *last_error = std::move(released.error);
    ++counters->errors;
    ++counters->dropped;
    return CaptureStatus::kFrameError;
  }
  frame->image = std::move(released.image);
  ++counters->frames;
  return CaptureStatus::kFrame;
}

}  // namespace silnet::node
