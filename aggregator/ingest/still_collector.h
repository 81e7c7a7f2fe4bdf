#pragma once
// Stills on command (issue 19): asks camera nodes for a still each (COMMAND_CAPTURE_STILL,
// the first frame at or after a frame of the node's own clock), collects the chunks of every
// photo and silhouette over DDS, asks again for chunks that are missing or arrive corrupt
// (COMMAND_RESEND_STILL) and for stills of nodes that have not answered, and returns what
// arrived, with every camera that did not answer in time reported by name and reason. It
// returns as soon as every camera whose node is present (its CameraInfo arrived) has its
// still; nodes that appear later are still waited for, up to the timeout.

#include <chrono>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/ingest/still_assembly.h"
#include "shared/dds/domain_config.h"
#include "shared/dds/qos.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// One camera to ask.
struct StillTarget {
  std::string camera_id;
  uint64_t from_frame = 0;  // the camera's frame index to take the still at or after (0: next)
};

// Settings of a collection.
struct StillCollectorOptions {
  dds::DomainConfig domain;
  dds::QosSettings qos;
  std::vector<StillTarget> targets;
  uint64_t still_id = 0;  // 0: derived from the clock (unique per request)
  // Stills of the empty scene: each node keeps its own as the background of its later
  // full-resolution stills (their silhouettes are empty).
  bool background = false;
  // Before asking, wait up to this long for the targets' nodes to appear (CameraInfo).
  std::chrono::milliseconds discovery{5000};
  // Give up on cameras whose stills are not complete by then (from the first request).
  std::chrono::milliseconds timeout{30000};
  // Ask again for a camera's missing chunks (or its still) after this long without news.
  std::chrono::milliseconds ask_again_after{800};
};

// What became of one camera's still.
struct CollectedStill {
  std::string camera_id;
  bool complete = false;
  std::string reason;  // why not complete
  uint64_t frame_index = 0;
  uint32_t frame_flags = 0;  // FrameFlags of the frame's silhouette on the node
  int64_t capture_time_ns = 0;
  std::string photo_encoding;
  cv::Mat photo;       // BGR
  cv::Mat silhouette;  // 0/255
  ChunkCounts chunks;
  uint64_t requests = 0;         // capture requests sent (1 unless repeated)
  uint64_t resend_requests = 0;  // chunk ranges asked for again
  uint64_t bad_images = 0;       // assembled images that failed to decode, fetched again
};

// The result of one collection.
struct StillCollection {
  uint64_t still_id = 0;
  std::vector<CollectedStill> cameras;  // in the targets' order
  double seconds = 0.0;

  size_t complete() const;
};

// Asks, collects and returns; `progress` (optional) counts completed cameras and may cancel.
// Throws DdsError if DDS cannot start, InputError for options that cannot work (no targets,
// an id longer than the wire allows).
StillCollection CollectStills(const StillCollectorOptions& options, Progress* progress = nullptr);

}  // namespace silnet::aggregator
