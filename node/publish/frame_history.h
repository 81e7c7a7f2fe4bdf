#pragma once
// The node's bounded local history of encoded frames: the last N HullFrame (and Contour)
// records of the current session, so an aggregator that restarted can ask for the frames it
// missed (COMMAND_RESEND). Thread-safe.

#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <vector>

#include "shared/io/frame_record.h"

namespace silnet::node {

// One frame's records.
struct HistoryEntry {
  FrameRecord hull;
  std::optional<FrameRecord> contour;
};

// Keeps the most recent `capacity` frames in frame-index order.
class FrameHistory {
 public:
  explicit FrameHistory(size_t capacity) : capacity_(capacity) {}

  // Adds a frame (indices must increase); the oldest frame goes when full.
  void Add(HistoryEntry entry);
  // The frames with index in [first, last] still held, in order.
  std::vector<HistoryEntry> Range(uint64_t first, uint64_t last) const;
  // Oldest and newest index held; nullopt when empty.
  std::optional<std::pair<uint64_t, uint64_t>> Span() const;
  size_t size() const;

 private:
  size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<HistoryEntry> entries_;
};

}  // namespace silnet::node
