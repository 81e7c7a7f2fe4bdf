#pragma once
// The aggregator's durable session store: every frame sample it accepts is appended to its
// camera's session log (shared/io/session_log.h) in one folder, crash-safe. Reopening the
// folder (after a crash or restart) recovers torn tails and re-indexes what is held, so a
// frame is never stored twice and nothing stored is lost.

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "shared/io/frame_record.h"
#include "shared/io/session_log.h"
#include "shared/io/session_log_reader.h"
#include "shared/record/record_log.h"
#include "shared/util/frame_index_set.h"

namespace silnet::aggregator {

// What happened to one sample offered to the store.
enum class StoreResult { kStored, kDuplicate, kFailed };

// True for a hull frame the node flagged dropped or unusable: no contour follows it.
bool HullHasNoContour(const FrameRecord& hull);

// Per camera session logs with duplicate detection.
class SessionStore {
 public:
  explicit SessionStore(std::filesystem::path dir);
  ~SessionStore();

  // Creates the folder, opens every existing log and indexes it. Throws InputError naming the
  // file for a log that cannot be opened or is not a session log.
  void Open();
  // Appends a HullFrame or Contour record unless the store holds it already (same camera,
  // session, frame index and type). kFailed (with the reason in last_error()) if the disk
  // refused it; the caller may offer it again later.
  StoreResult Add(SessionRecordType type, const FrameRecord& record);
  // Appends a camera description (always stored: the latest one wins on reading).
  StoreResult AddCameraInfo(const CameraInfoRecord& info);
  // The hull frame indices held for a camera's session (empty set if none).
  FrameIndexSet HullFrames(const std::string& camera_id, uint32_t session) const;
  // The hull frames held for a camera's session that the node flagged dropped or unusable:
  // no contour follows them (empty set if none).
  FrameIndexSet HullFramesWithoutContour(const std::string& camera_id, uint32_t session) const;
  // True if the store holds the contour of that frame.
  bool HasContour(const std::string& camera_id, uint32_t session, uint64_t frame_index) const;
  // True if the store holds any contour of that session.
  bool HasAnyContour(const std::string& camera_id, uint32_t session) const;
  // Sessions held for a camera, ascending.
  std::vector<uint32_t> Sessions(const std::string& camera_id) const;
  std::vector<std::string> Cameras() const;
  // Flushes every log to the device.
  void Flush();
  std::string last_error() const;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  struct Camera;
  Camera& CameraFor(const std::string& camera_id);

  std::filesystem::path dir_;
  mutable std::mutex mutex_;
  std::map<std::string, std::unique_ptr<Camera>> cameras_;
  std::string last_error_;
};

}  // namespace silnet::aggregator
