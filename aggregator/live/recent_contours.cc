#include "aggregator/live/recent_contours.h"

#include <fmt/format.h>

#include "shared/util/check.h"

namespace silnet::aggregator {

void RecentContours::Add(const FrameRecord& record) {
  std::lock_guard lock(mutex_);
  if (closed_) return;
  Camera& camera = cameras_[record.camera_id];
  if (record.session < camera.session) return;
  if (record.session > camera.session) {
    camera = Camera{};
    camera.session = record.session;
  }
  if (record.frame_index >= camera.floor)
    camera.contours.insert_or_assign(record.frame_index, record);
}

void RecentContours::DropBefore(const std::string& id, uint64_t frame) {
  std::lock_guard lock(mutex_);
  const auto it = cameras_.find(id);
  if (it == cameras_.end() || frame <= it->second.floor) return;
  Camera& camera = it->second;
  camera.floor = frame;
  camera.contours.erase(camera.contours.begin(), camera.contours.lower_bound(frame));
}

void RecentContours::Close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  cameras_.clear();
}

bool RecentContours::Holds(const std::string& id, uint64_t first) const {
  std::lock_guard lock(mutex_);
  const auto it = cameras_.find(id);
  if (it == cameras_.end() || first < it->second.floor) return false;
  const auto& contours = it->second.contours;
  return !contours.empty() && contours.begin()->first <= first;
}

size_t RecentContours::size() const {
  std::lock_guard lock(mutex_);
  size_t n = 0;
  for (const auto& [id, camera] : cameras_)
    n += camera.contours.size();
  return n;
}

std::vector<std::string> RecentContours::CameraIds() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> ids;
  for (const auto& [id, camera] : cameras_) {
    if (!camera.contours.empty()) ids.push_back(id);
  }
  return ids;
}

int RecentContours::FrameCount(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = cameras_.find(id);
  if (it == cameras_.end() || it->second.contours.empty()) return 0;
  return static_cast<int>(it->second.contours.rbegin()->first + 1);
}

cv::Mat RecentContours::Mask(const CameraModel& camera, int frame) const {
  FrameRecord record;
  {
    std::lock_guard lock(mutex_);
    const FrameRecord* held = nullptr;
    if (const auto it = cameras_.find(camera.id); it != cameras_.end() && frame >= 0) {
      const auto found = it->second.contours.find(static_cast<uint64_t>(frame));
      if (found != it->second.contours.end()) held = &found->second;
    }
    if (held == nullptr) {
      throw InputError(
          fmt::format("{} is not held (dropped, or not received)", Where(camera.id, frame)));
    }
    record = *held;
  }
  return ContourRecordMask(record, camera, Where(camera.id, frame));
}

std::string RecentContours::Where(const std::string& id, int frame) const {
  return fmt::format("the contour of {} frame {} in memory (store {})", id, frame, store_.string());
}

}  // namespace silnet::aggregator
