#include "node/publish/still_store.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "node/segmentation/weak_silhouette.h"
#include "shared/util/check.h"

namespace silnet::node {

EncodedStill EncodeStill(uint64_t still_id, uint64_t frame_index, uint32_t frame_flags,
                         int64_t capture_time_ns, const cv::Mat& photo, const cv::Mat& silhouette,
                         int64_t jpeg_above_pixels) {
  if (photo.empty() || silhouette.empty()) throw InputError("a still needs a photo and a mask");
  if (photo.size() != silhouette.size()) {
    throw InputError("the still's photo and silhouette differ in size");
  }
  EncodedStill still;
  still.still_id = still_id;
  still.frame_index = frame_index;
  still.frame_flags = frame_flags;
  still.capture_time_ns = capture_time_ns;
  still.width = photo.cols;
  still.height = photo.rows;
  const bool jpeg = static_cast<int64_t>(photo.total()) > jpeg_above_pixels;
  still.photo_encoding = jpeg ? "jpeg" : "png";
  const std::vector<int> jpeg_params{cv::IMWRITE_JPEG_QUALITY, 95};
  if (!cv::imencode(jpeg ? ".jpg" : ".png", photo, still.photo,
                    jpeg ? jpeg_params : std::vector<int>{})) {
    throw InputError("the still's photo could not be encoded");
  }
  if (silhouette.channels() != 1) throw InputError("the still's silhouette must have one channel");
  cv::Mat binary;
  cv::compare(silhouette, 0, binary, cv::CMP_NE);
  binary.setTo(kWeakSilhouette, silhouette == kWeakSilhouette);
  if (!cv::imencode(".png", binary, still.silhouette)) {
    throw InputError("the still's silhouette could not be encoded");
  }
  return still;
}

void StillRequests::Add(uint64_t still_id, uint64_t from_frame) {
  std::lock_guard lock(mutex_);
  for (const auto& [id, from] : waiting_)
    if (id == still_id) return;
  waiting_.emplace_back(still_id, from_frame);
}

std::vector<uint64_t> StillRequests::TakeDue(uint64_t frame_index) {
  std::lock_guard lock(mutex_);
  std::vector<uint64_t> due;
  std::erase_if(waiting_, [&](const std::pair<uint64_t, uint64_t>& request) {
    if (request.second > frame_index) return false;
    due.push_back(request.first);
    return true;
  });
  return due;
}

size_t StillRequests::waiting() const {
  std::lock_guard lock(mutex_);
  return waiting_.size();
}

void StillStore::Add(EncodedStill still) {
  std::lock_guard lock(mutex_);
  std::erase_if(stills_, [&](const EncodedStill& s) { return s.still_id == still.still_id; });
  stills_.push_back(std::move(still));
  while (stills_.size() > capacity_)
    stills_.pop_front();
}

std::optional<EncodedStill> StillStore::Find(uint64_t still_id) const {
  std::lock_guard lock(mutex_);
  for (const EncodedStill& s : stills_)
    if (s.still_id == still_id) return s;
  return std::nullopt;
}

}  // namespace silnet::node
