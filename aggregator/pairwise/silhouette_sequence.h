#pragma once
// A camera's silhouettes over time, as the pairwise estimator uses them: per frame index,
// the decoded convex hull with its clipped-edge bits and tangent table (thesis 2.3.1).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "shared/io/frame_record.h"
#include "shared/silhouette/silhouette_hull.h"

namespace silnet::aggregator {

// One frame's silhouette.
struct SilhouetteFrame {
  uint64_t index = 0;
  int64_t capture_time_ns = 0;
  uint32_t flags = 0;  // silnet_wire_FRAME_* bits
  SilhouetteHull hull;
};

// A camera's frames of one session, sorted by index.
struct SilhouetteSequence {
  std::string camera_id;
  int width = 0;
  int height = 0;
  double fps = 30.0;
  std::vector<SilhouetteFrame> frames;

  // The frame with index `index` if it is held and usable (a non-empty hull, not flagged
  // empty, saturated, bad or dropped; warm-up frames only if `allow_warmup`); else null.
  const SilhouetteFrame* Usable(uint64_t index) const;
  // Index range [first, last] of the frames held.
  uint64_t first_index() const { return frames.empty() ? 0 : frames.front().index; }
  uint64_t last_index() const { return frames.empty() ? 0 : frames.back().index; }
  // Number of usable frames.
  size_t UsableCount() const;

  bool allow_warmup = false;

  // Builds the index lookup; call after filling `frames` (sorted by index).
  void Index();

 private:
  std::vector<int32_t> position_;  // frame index - first_index() -> position, or -1
};

// A stored hull record decoded as the estimator uses it; an undecodable hull leaves the
// frame flagged FRAME_BAD_INPUT with an empty hull.
SilhouetteFrame DecodeSilhouetteFrame(const FrameRecord& record);

// Where sequences come from.
enum class SequenceSource {
  kSessionLogs,   // *.silnetlog files (an aggregator store or a node's --record folder)
  kMaskDataset,   // <camera>/masks/%06d.png, run through the node's encoder
  kFrameDataset,  // <camera>/frames/%06d.png, segmented by the node's pipeline
  kMaskVideo,     // <camera>/<mask_video>: silhouettes as a video, thresholded at mask_threshold
  kFrameVideo,    // <camera>/<frame_video>: colour video, segmented by the node's pipeline
};

// Options of LoadSequences.
struct SequenceLoadOptions {
  int max_frames = 0;         // 0 = all
  int first_frame = 0;        // first frame index to read
  bool allow_warmup = false;  // use frames flagged FRAME_WARMUP
  int threads = 0;            // datasets: cameras read in parallel (0 = all cores)
  std::string mask_video;     // file name of each camera's mask video; empty = no video input
  std::string frame_video;    // file name of each camera's colour video (segmented); or empty
  double video_fps = 0.0;     // mask videos: frame rate (0 = the container's)
};

// Reads every camera's silhouettes from `input`: a folder of session logs (or one holding
// sessions/), a dataset folder with masks/ (or frames/) per camera, or, when
// `options.mask_video` names a file, camera folders holding such a mask video (decoded
// frames thresholded by the node's mask input, so a lossy codec's blurred edges fall at half
// grey), or when `options.frame_video` does, colour videos segmented by the node's pipeline. For
// session logs the newest session of each camera is used. Throws InputError naming the input if it
// holds none of these, or if a file is unreadable.
std::vector<SilhouetteSequence> LoadSequences(const std::filesystem::path& input,
                                              const SequenceLoadOptions& options = {},
                                              SequenceSource* detected = nullptr);

}  // namespace silnet::aggregator
