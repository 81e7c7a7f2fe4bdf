#pragma once
// What the replayed sources (image folders, video files) share: a decoded frame waiting for
// its due time, and how it is handed out.

#include <chrono>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>

#include "node/capture/capture_source.h"
#include "node/capture/frame_pacer.h"

namespace silnet::node {

// A decoded frame, or the reason it cannot be delivered, waiting for its due time.
struct ReplayedFrame {
  uint64_t position = 0;  // n: frames of this stream before this one (after first_frame)
  cv::Mat image;          // empty if `error` is set
  std::string error;
};

// Hands `*pending` (set) out as `frame`: frame_index first_frame + position, capture time its
// due time when `pacer` is set, else the clock now. With `real_time` (which needs `pacer`) it
// first waits up to `timeout` for the due time; if the frame is not due by then it returns
// kTimeout and `*pending` stays for the next call. Otherwise `*pending` is emptied: a frame
// with an error is kFrameError (counted as an error and as dropped, its reason in
// `*last_error`), any other kFrame (counted in frames).
CaptureStatus DeliverReplayedFrame(std::optional<ReplayedFrame>* pending,
                                   const std::optional<FramePacer>& pacer, bool real_time,
                                   uint64_t first_frame, std::chrono::milliseconds timeout,
                                   CapturedFrame* frame, CaptureCounters* counters,
                                   std::string* last_error);

}  // namespace silnet::node
