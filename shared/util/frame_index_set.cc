#include "shared/util/frame_index_set.h"

#include <algorithm>

namespace silnet {

bool FrameIndexSet::Insert(uint64_t index) {
  // First range whose end is >= index - 1 (could absorb or contain the index).
  auto it = std::lower_bound(ranges_.begin(), ranges_.end(), index,
                             [](const FrameRange& r, uint64_t i) { return r.last + 1 < i; });
  if (it != ranges_.end() && it->first <= index && index <= it->last) return false;
  if (it != ranges_.end() && it->last + 1 == index) {
    it->last = index;
    auto next = it + 1;
    if (next != ranges_.end() && next->first == index + 1) {
      it->last = next->last;
      ranges_.erase(next);
    }
    return true;
  }
  if (it != ranges_.end() && it->first == index + 1) {
    it->first = index;
    return true;
  }
  ranges_.insert(it, FrameRange{index, index});
  return true;
}

bool FrameIndexSet::Contains(uint64_t index) const {
  auto it = std::lower_bound(ranges_.begin(), ranges_.end(), index,
                             [](const FrameRange& r, uint64_t i) { return r.last < i; });
  return it != ranges_.end() && it->first <= index;
}

uint64_t FrameIndexSet::size() const {
  uint64_t total = 0;
  for (const FrameRange& r : ranges_)
    total += r.last - r.first + 1;
  return total;
}

std::vector<FrameRange> FrameIndexSet::Missing(uint64_t from) const {
  std::vector<FrameRange> gaps;
  uint64_t next = from;
  for (const FrameRange& r : ranges_) {
    if (r.last < next) continue;
    if (r.first > next) gaps.push_back({next, r.first - 1});
    next = r.last + 1;
  }
  return gaps;
}

}  // namespace silnet
