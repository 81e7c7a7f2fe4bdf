#include "aggregator/live/recent_silhouettes.h"

namespace silnet::aggregator {

void RecentSilhouettes::Add(const FrameRecord& record) {
  SilhouetteFrame frame = DecodeSilhouetteFrame(record);
  std::lock_guard lock(mutex_);
  Camera& camera = cameras_[record.camera_id];
  if (record.session < camera.session) return;
  if (record.session > camera.session) {
    camera.session = record.session;
    camera.frames.clear();
  }
  camera.width = record.width;
  camera.height = record.height;
  if (record.frame_index >= floor_)
    camera.frames.insert_or_assign(record.frame_index, std::move(frame));
}

void RecentSilhouettes::DropBefore(uint64_t frame) {
  std::lock_guard lock(mutex_);
  floor_ = frame;
  for (auto& [id, camera] : cameras_)
    camera.frames.erase(camera.frames.begin(), camera.frames.lower_bound(frame));
}

std::vector<SilhouetteSequence> RecentSilhouettes::Window(uint64_t first, uint64_t count) const {
  std::lock_guard lock(mutex_);
  std::vector<SilhouetteSequence> out;
  for (const auto& [id, camera] : cameras_) {
    SilhouetteSequence sequence;
    sequence.camera_id = id;
    sequence.width = camera.width;
    sequence.height = camera.height;
    for (auto it = camera.frames.lower_bound(first);
         it != camera.frames.end() && it->first < first + count; ++it)
      sequence.frames.push_back(it->second);
    if (sequence.frames.empty()) continue;
    sequence.Index();
    out.push_back(std::move(sequence));
  }
  return out;
}

bool RecentSilhouettes::Holds(uint64_t first) const {
  std::lock_guard lock(mutex_);
  if (first < floor_ || cameras_.empty()) return false;
  for (const auto& [id, camera] : cameras_) {
    if (camera.frames.empty() || camera.frames.begin()->first > first) return false;
  }
  return true;
}

size_t RecentSilhouettes::size() const {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const auto& [id, camera] : cameras_)
    n += camera.frames.size();
  return n;
}

}  // namespace silnet::aggregator
