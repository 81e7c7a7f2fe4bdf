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

// How a replayed source (image folder, video file) delivers its frames: what every one's
// options share.
struct ReplayOptions {
  // Expected frame size; both 0 take the size of the first frame (or the video container's).
  int width = 0;
  int height = 0;
  // Nominal frame rate; 0 = unknown (a video then takes its container's rate, if it states
  // one); timestamps are the time of Read() when no rate is known.
  double fps = 0.0;
  // Release each frame no earlier than its due time (needs a known frame rate).
  bool real_time = false;
  // CLOCK_REALTIME instant of reference time 0; 0 = the time of Open().
  int64_t start_ns = 0;
  // Time offset of this camera in frames: the n-th delivered frame (n = 0, 1, ...) is due at
  // start + (n + offset_frames) / fps.
  double offset_frames = 0.0;
  // Position of the first frame to deliver (file-name order in a folder, decode order in a
  // video; earlier frames are skipped).
  uint64_t first_frame = 0;
  // Number of frames to deliver at most; 0 = all.
  uint64_t max_frames = 0;
};

// Throws CaptureError, prefixed by `source` (e.g. "image folder /data/cam0"), if `options`
// give only one of width and height, a negative size, or a frame rate that is negative or
// not finite.
void CheckReplayOptions(const ReplayOptions& options, const std::string& source);

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
