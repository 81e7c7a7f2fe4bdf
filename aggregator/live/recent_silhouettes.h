#pragma once
// The newest hull frames of every camera's current session, decoded and held in memory as
// the ingest service stores them, so that work on recent windows (the camera motion watch)
// does not read the session logs again. Frames below a moving floor are dropped; a camera's
// newer session replaces its older one. Thread-safe: filled by the ingest loop, read by
// background steps.

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "aggregator/pairwise/silhouette_sequence.h"
#include "shared/io/frame_record.h"

namespace silnet::aggregator {

// A rolling store of decoded hull frames per camera.
class RecentSilhouettes {
 public:
  // Takes a stored hull frame (a frame of an older session than the camera's current one is
  // ignored; a newer session starts the camera over).
  void Add(const FrameRecord& record);
  // Drops every frame below `frame`.
  void DropBefore(uint64_t frame);
  // Every camera's frames [first, first + count) that are held, as sequences sorted by
  // camera id (cameras without such frames are left out).
  std::vector<SilhouetteSequence> Window(uint64_t first, uint64_t count) const;
  // True if every camera's frames from `first` on are held (none dropped below it, none
  // stored before this holder started following the streams).
  bool Holds(uint64_t first) const;
  // Frames held over all cameras.
  size_t size() const;

 private:
  struct Camera {
    uint32_t session = 0;
    int width = 0, height = 0;
    std::map<uint64_t, SilhouetteFrame> frames;
  };
  mutable std::mutex mutex_;
  uint64_t floor_ = 0;
  std::map<std::string, Camera> cameras_;
};

}  // namespace silnet::aggregator
