#include "node/publish/frame_history.h"

#include <algorithm>

namespace silnet::node {

void FrameHistory::Add(HistoryEntry entry) {
  std::lock_guard lock(mutex_);
  if (capacity_ == 0) return;
  if (entries_.size() >= capacity_) entries_.pop_front();
  entries_.push_back(std::move(entry));
}

std::vector<HistoryEntry> FrameHistory::Range(uint64_t first, uint64_t last) const {
  std::lock_guard lock(mutex_);
  std::vector<HistoryEntry> out;
  auto begin = std::lower_bound(
      entries_.begin(), entries_.end(), first,
      [](const HistoryEntry& e, uint64_t index) { return e.hull.frame_index < index; });
  for (auto it = begin; it != entries_.end() && it->hull.frame_index <= last; ++it)
    out.push_back(*it);
  return out;
}

std::optional<std::pair<uint64_t, uint64_t>> FrameHistory::Span() const {
  std::lock_guard lock(mutex_);
  if (entries_.empty()) return std::nullopt;
  return std::make_pair(entries_.front().hull.frame_index, entries_.back().hull.frame_index);
}

size_t FrameHistory::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

}  // namespace silnet::node
