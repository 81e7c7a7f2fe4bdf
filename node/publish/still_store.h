#pragma once
// The node's stills (COMMAND_CAPTURE_STILL): requests waiting for their frame, the encoding
// of a photograph and its silhouette, and the last few encoded stills kept so the aggregator
// can ask for lost or corrupt chunks again (COMMAND_RESEND_STILL). Transport-free.

#include <cstdint>
#include <deque>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

namespace silnet::node {

// One still, encoded as it goes on the wire.
struct EncodedStill {
  uint64_t still_id = 0;
  uint64_t frame_index = 0;  // the camera's frame it was taken from
  uint32_t frame_flags = 0;  // FrameFlags of that frame's silhouette
  int64_t capture_time_ns = 0;
  int width = 0, height = 0;
  std::string photo_encoding;  // "png" or "jpeg"
  std::vector<uint8_t> photo;
  std::vector<uint8_t> silhouette;  // always PNG, 0/255 (and kWeakSilhouette)
};

// Encodes a photograph (PNG, or JPEG at quality 95 when it has more than
// `jpeg_above_pixels` pixels) and its silhouette (PNG: weak evidence, kWeakSilhouette, stays;
// any other non-zero pixel becomes 255).
// Throws InputError when the two differ in size or either is empty.
EncodedStill EncodeStill(uint64_t still_id, uint64_t frame_index, uint32_t frame_flags,
                         int64_t capture_time_ns, const cv::Mat& photo, const cv::Mat& silhouette,
                         int64_t jpeg_above_pixels = 8'000'000);

// Capture requests waiting for their frame. Thread-safe.
class StillRequests {
 public:
  // Asks for still `still_id` from the first frame whose index is `from_frame` or later
  // (0: the next frame). A request for an id already waiting is ignored.
  void Add(uint64_t still_id, uint64_t from_frame);
  // The requests a frame of index `frame_index` satisfies, removed from the waiting list.
  std::vector<uint64_t> TakeDue(uint64_t frame_index);
  size_t waiting() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::pair<uint64_t, uint64_t>> waiting_;  // (still id, from frame)
};

// The last `capacity` encoded stills, by id. Thread-safe.
class StillStore {
 public:
  explicit StillStore(size_t capacity = 4) : capacity_(capacity) {}
  // Keeps `still`, forgetting the oldest beyond the capacity.
  void Add(EncodedStill still);
  // A copy of still `still_id`, if it is still held.
  std::optional<EncodedStill> Find(uint64_t still_id) const;

 private:
  size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<EncodedStill> stills_;
};

}  // namespace silnet::node
