#pragma once
// Reassembles one camera's still (photo and silhouette) from its Still chunks: each chunk is
// checked (its CRC-32, its index, and that it agrees with the chunks before it on size,
// encoding and the whole image's CRC-32), kept once, and the missing ones are listed so they
// can be asked for again. A part is complete when every chunk is held and the whole image's
// CRC-32 matches; decoding then checks the image is what the chunks said it is.
// Transport-free: the still collector feeds it samples.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "silnet.h"

namespace silnet::aggregator {

// What became of one chunk.
enum class ChunkVerdict {
  kAccepted,   // new and intact
  kDuplicate,  // already held
  kCorrupt,    // its CRC-32 does not match its data: to be asked for again
  kMalformed,  // inconsistent with the still (index, count, size, encoding, image CRC)
};

// Counts of one camera's chunks.
struct ChunkCounts {
  uint64_t accepted = 0, duplicates = 0, corrupt = 0, malformed = 0;
};

// The chunks of one part (photo or silhouette) of one still.
class StillPartAssembly {
 public:
  // Checks and keeps `sample` (of this part).
  ChunkVerdict Accept(const silnet_wire_Still& sample);
  bool started() const { return !chunks_.empty(); }
  // Every chunk held and the whole image's CRC-32 matches.
  bool Complete() const { return complete_; }
  // Ranges [first, last] of chunks not held (empty before the first chunk arrived).
  std::vector<std::pair<uint32_t, uint32_t>> Missing() const;
  // The encoded image, once complete.
  std::vector<uint8_t> Bytes() const;
  // Forgets every chunk (the assembled image failed to decode: all are asked for again).
  void Reset();

  // What the first chunk announced (valid once started()).
  int width = 0, height = 0;
  uint64_t frame_index = 0;
  uint32_t frame_flags = 0;
  int64_t capture_time_ns = 0;
  std::string encoding;

 private:
  uint32_t chunk_count_ = 0;
  uint64_t image_bytes_ = 0;
  uint32_t image_crc_ = 0;
  std::vector<std::optional<std::vector<uint8_t>>> chunks_;
  size_t held_ = 0;        // chunks held
  bool complete_ = false;  // checked once, when the last chunk arrived
};

// A camera's still as it arrives.
class StillAssembly {
 public:
  explicit StillAssembly(uint64_t still_id) : still_id_(still_id) {}

  // Checks and keeps a chunk of this still (a chunk of another still is malformed).
  ChunkVerdict Accept(const silnet_wire_Still& sample);
  StillPartAssembly& part(silnet_wire_StillPart p) {
    return p == silnet_wire_STILL_PHOTO ? photo_ : silhouette_;
  }
  bool Complete() const { return photo_.Complete() && silhouette_.Complete(); }
  // Decodes a complete still into `photo` (BGR) and `silhouette` (0/255, one channel, and
  // node::kWeakSilhouette where the node marked weak evidence).
  // Returns an empty string, or why it is unusable (undecodable, sizes not as announced,
  // photo and silhouette of different frames); the part at fault is reset so that its
  // chunks are asked for again.
  std::string Decode(cv::Mat* photo, cv::Mat* silhouette);
  const ChunkCounts& counts() const { return counts_; }

 private:
  uint64_t still_id_;
  StillPartAssembly photo_, silhouette_;
  ChunkCounts counts_;
};

}  // namespace silnet::aggregator
