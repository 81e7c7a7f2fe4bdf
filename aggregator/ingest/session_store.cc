#include "aggregator/ingest/session_store.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "shared/util/check.h"
#include "silnet.h"

namespace silnet::aggregator {

bool HullHasNoContour(const FrameRecord& hull) {
  return (hull.flags & (silnet_wire_FRAME_DROPPED | silnet_wire_FRAME_BAD_INPUT)) != 0;
}

struct SessionStore::Camera {
  RecordLogWriter writer;
  // Indices held per session, for hull frames, contours, and hull frames without contour.
  std::map<uint32_t, FrameIndexSet> hulls, contours, without_contour;

  void IndexHull(uint32_t session, const FrameRecord& hull) {
    hulls[session].Insert(hull.frame_index);
    if (HullHasNoContour(hull)) without_contour[session].Insert(hull.frame_index);
  }
};

SessionStore::SessionStore(std::filesystem::path dir) : dir_(std::move(dir)) {}
SessionStore::~SessionStore() {
  Flush();
}

void SessionStore::Open() {
  std::error_code error;
  std::filesystem::create_directories(dir_, error);
  if (error) throw InputError("cannot create " + dir_.string() + ": " + error.message());
  for (const std::string& id : SessionLogCameras(dir_)) {
    SessionReadReport report;
    const std::vector<SessionFrames> sessions = ReadSessionLog(SessionLogPath(dir_, id), &report);
    Camera& camera = CameraFor(id);
    for (const SessionFrames& s : sessions) {
      for (const FrameRecord& r : s.hulls)
        camera.IndexHull(s.session, r);
      for (const FrameRecord& r : s.contours)
        camera.contours[s.session].Insert(r.frame_index);
    }
    spdlog::info("session store: {} holds {} records in {} sessions", id, report.records,
                 sessions.size());
  }
}

SessionStore::Camera& SessionStore::CameraFor(const std::string& camera_id) {
  auto it = cameras_.find(camera_id);
  if (it != cameras_.end()) return *it->second;
  auto camera = std::make_unique<Camera>();
  const RecordLogStatus status =
      camera->writer.Open(SessionLogPath(dir_, camera_id), kSessionLogStreamKind);
  if (!status.ok()) throw InputError("session store: " + status.message());
  if (camera->writer.recovery().tail_truncated) {
    spdlog::warn("session store: {}: cut a torn tail of {} bytes", camera_id,
                 camera->writer.recovery().bytes_truncated);
  }
  return *cameras_.emplace(camera_id, std::move(camera)).first->second;
}

StoreResult SessionStore::Add(SessionRecordType type, const FrameRecord& record) {
  std::lock_guard lock(mutex_);
  Camera& camera = CameraFor(record.camera_id);
  FrameIndexSet& held =
      (type == SessionRecordType::kContour ? camera.contours : camera.hulls)[record.session];
  if (held.Contains(record.frame_index)) return StoreResult::kDuplicate;
  const RecordLogStatus status =
      camera.writer.Append(static_cast<uint16_t>(type), SerializeFrameRecord(record));
  if (!status.ok()) {
    last_error_ = status.message();
    return StoreResult::kFailed;
  }
  if (type == SessionRecordType::kContour) {
    held.Insert(record.frame_index);
  } else {
    camera.IndexHull(record.session, record);
  }
  return StoreResult::kStored;
}

StoreResult SessionStore::AddCameraInfo(const CameraInfoRecord& info) {
  std::lock_guard lock(mutex_);
  Camera& camera = CameraFor(info.camera_id);
  const RecordLogStatus status = camera.writer.Append(
      static_cast<uint16_t>(SessionRecordType::kCameraInfo), SerializeCameraInfo(info));
  if (!status.ok()) {
    last_error_ = status.message();
    return StoreResult::kFailed;
  }
  return StoreResult::kStored;
}

FrameIndexSet SessionStore::HullFrames(const std::string& camera_id, uint32_t session) const {
  std::lock_guard lock(mutex_);
  auto it = cameras_.find(camera_id);
  if (it == cameras_.end()) return {};
  auto s = it->second->hulls.find(session);
  return s == it->second->hulls.end() ? FrameIndexSet{} : s->second;
}

FrameIndexSet SessionStore::HullFramesWithoutContour(const std::string& camera_id,
                                                     uint32_t session) const {
  std::lock_guard lock(mutex_);
  auto it = cameras_.find(camera_id);
  if (it == cameras_.end()) return {};
  auto s = it->second->without_contour.find(session);
  return s == it->second->without_contour.end() ? FrameIndexSet{} : s->second;
}

bool SessionStore::HasContour(const std::string& camera_id, uint32_t session,
                              uint64_t frame_index) const {
  std::lock_guard lock(mutex_);
  auto it = cameras_.find(camera_id);
  if (it == cameras_.end()) return false;
  auto s = it->second->contours.find(session);
  return s != it->second->contours.end() && s->second.Contains(frame_index);
}

bool SessionStore::HasAnyContour(const std::string& camera_id, uint32_t session) const {
  std::lock_guard lock(mutex_);
  auto it = cameras_.find(camera_id);
  if (it == cameras_.end()) return false;
  auto s = it->second->contours.find(session);
  return s != it->second->contours.end() && !s->second.empty();
}

std::vector<uint32_t> SessionStore::Sessions(const std::string& camera_id) const {
  std::lock_guard lock(mutex_);
  std::vector<uint32_t> sessions;
  auto it = cameras_.find(camera_id);
  if (it != cameras_.end()) {
    for (const auto& [session, frames] : it->second->hulls)
      sessions.push_back(session);
  }
  return sessions;
}

std::vector<std::string> SessionStore::Cameras() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> ids;
  for (const auto& [id, camera] : cameras_)
    ids.push_back(id);
  return ids;
}

void SessionStore::Flush() {
  std::lock_guard lock(mutex_);
  for (auto& [id, camera] : cameras_) {
    const RecordLogStatus status = camera->writer.Flush();
    if (!status.ok()) last_error_ = status.message();
  }
}

std::string SessionStore::last_error() const {
  std::lock_guard lock(mutex_);
  return last_error_;
}

}  // namespace silnet::aggregator
