#pragma once
// The contours of every camera's current session as the ingest service stores them, held in
// memory so that the live job's hull batches read them from here instead of reading the
// session logs again for every batch. Each camera's contours below its own floor (the
// first frame the next batch can need, which differs between cameras by their time offsets)
// are dropped; a camera's newer session replaces its older one. Thread-safe: filled by the
// ingest loop, read by the hull batch running in the background.

#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "aggregator/hulls/silhouette_source.h"
#include "shared/io/frame_record.h"

namespace silnet::aggregator {

// A rolling store of Contour records per camera, readable as a SilhouetteSource.
class RecentContours : public SilhouetteSource {
 public:
  // `store` is the session store the records also go to (named in messages).
  explicit RecentContours(std::filesystem::path store) : store_(std::move(store)) {}

  // Takes a stored Contour record (a frame of an older session than the camera's current one
  // is ignored; a newer session starts the camera over).
  void Add(const FrameRecord& record);
  // Drops `camera`'s contours below `frame`.
  void DropBefore(const std::string& camera, uint64_t frame);
  // Drops every contour and takes no more (no batch will read them).
  void Close();
  // True if `camera`'s contours from `first` on are all here: none dropped below it, and the
  // camera's stream followed since before it (the first held frame is not after `first`).
  bool Holds(const std::string& camera, uint64_t first) const;
  // Contours held over all cameras.
  size_t size() const;

  std::vector<std::string> CameraIds() const override;
  int FrameCount(const std::string& camera) const override;
  cv::Mat Mask(const CameraModel& camera, int frame) const override;
  std::string Where(const std::string& camera, int frame) const override;
  const std::filesystem::path& root() const override { return store_; }

 private:
  struct Camera {
    uint32_t session = 0;
    uint64_t floor = 0;
    std::map<uint64_t, FrameRecord> contours;
  };
  std::filesystem::path store_;
  mutable std::mutex mutex_;
  bool closed_ = false;
  std::map<std::string, Camera> cameras_;
};

}  // namespace silnet::aggregator
