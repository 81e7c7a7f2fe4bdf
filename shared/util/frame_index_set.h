#pragma once
// A set of frame indices kept as sorted disjoint intervals: which frames of a camera's
// session have arrived, and which are missing below the newest.

#include <cstdint>
#include <utility>
#include <vector>

namespace silnet {

// Inclusive interval [first, last] of frame indices.
struct FrameRange {
  uint64_t first = 0;
  uint64_t last = 0;
  bool operator==(const FrameRange&) const = default;
};

// Sorted disjoint intervals of frame indices.
class FrameIndexSet {
 public:
  // Adds an index; false if it was already present.
  bool Insert(uint64_t index);
  bool Contains(uint64_t index) const;
  // Number of indices held.
  uint64_t size() const;
  bool empty() const { return ranges_.empty(); }
  // Smallest and largest index; the set must not be empty.
  uint64_t min() const { return ranges_.front().first; }
  uint64_t max() const { return ranges_.back().last; }
  // The gaps between `from` and the largest index held.
  std::vector<FrameRange> Missing(uint64_t from = 0) const;
  const std::vector<FrameRange>& ranges() const { return ranges_; }

 private:
  std::vector<FrameRange> ranges_;
};

}  // namespace silnet
