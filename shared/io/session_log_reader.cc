#include "shared/io/session_log_reader.h"

#include <algorithm>
#include <map>

#include "shared/record/record_log.h"
#include "shared/util/check.h"
#include "shared/util/frame_index_set.h"

namespace silnet {

std::vector<SessionFrames> ReadSessionLog(const std::filesystem::path& path,
                                          SessionReadReport* report) {
  RecordLogReader reader;
  RecordLogReaderOptions options;
  options.expected_stream_kind = kSessionLogStreamKind;
  const RecordLogStatus status = reader.Open(path, options);
  if (!status.ok()) throw InputError(status.message());
  SessionReadReport local;
  SessionReadReport& r = report != nullptr ? *report : local;
  std::map<uint32_t, SessionFrames> sessions;
  std::map<uint32_t, std::pair<FrameIndexSet, FrameIndexSet>> seen;
  CameraInfoRecord info;
  Record record;
  ReadStatus read;
  while ((read = reader.Next(&record)) == ReadStatus::kOk) {
    ++r.records;
    const auto type = static_cast<SessionRecordType>(record.type);
    if (type == SessionRecordType::kCameraInfo) {
      if (!ParseCameraInfo(record.payload, &info, nullptr)) ++r.malformed;
      continue;
    }
    FrameRecord frame;
    if ((type != SessionRecordType::kHullFrame && type != SessionRecordType::kContour) ||
        !ParseFrameRecord(record.payload, &frame, nullptr)) {
      ++r.malformed;
      continue;
    }
    auto& [hull_seen, contour_seen] = seen[frame.session];
    FrameIndexSet& held = type == SessionRecordType::kHullFrame ? hull_seen : contour_seen;
    if (!held.Insert(frame.frame_index)) {
      ++r.duplicates;
      continue;
    }
    SessionFrames& s = sessions[frame.session];
    s.camera_id = frame.camera_id;
    s.session = frame.session;
    (type == SessionRecordType::kHullFrame ? s.hulls : s.contours).push_back(std::move(frame));
  }
  r.torn_tail = read == ReadStatus::kTornTail;
  if (read == ReadStatus::kCorrupt || read == ReadStatus::kIoError) {
    r.problem = std::string(ToString(read)) + " at byte " +
                std::to_string(reader.problem_offset()) + ": " + reader.problem();
  }
  std::vector<SessionFrames> out;
  auto by_index = [](const FrameRecord& a, const FrameRecord& b) {
    return a.frame_index < b.frame_index;
  };
  for (auto& [session, s] : sessions) {
    std::sort(s.hulls.begin(), s.hulls.end(), by_index);
    std::sort(s.contours.begin(), s.contours.end(), by_index);
    s.info = info;
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace silnet
