#pragma once
// Reads a camera's session log (shared/io/session_log.h) back into frames: every session's
// hull and contour records sorted by frame index, duplicates and malformed records counted
// and skipped, a torn tail or corruption reported rather than thrown.

#include <filesystem>
#include <string>
#include <vector>

#include "shared/io/frame_record.h"
#include "shared/io/session_log.h"

namespace silnet {

// One camera's frames of one session, read back from a session log, sorted by frame index.
struct SessionFrames {
  std::string camera_id;
  uint32_t session = 0;
  std::vector<FrameRecord> hulls;     // one per frame index
  std::vector<FrameRecord> contours;  // one per frame index that has one
  CameraInfoRecord info;              // the latest description seen for the camera
};

// What reading a log found besides the frames.
struct SessionReadReport {
  uint64_t records = 0;
  uint64_t duplicates = 0;  // repeated (session, index, type) records, ignored
  uint64_t malformed = 0;   // records that did not parse, ignored
  bool torn_tail = false;   // an incomplete last record (a writer still writing, or a crash)
  std::string problem;      // corruption met (reading stopped there), empty if none
};

// Reads a camera's session log. Sessions are returned ascending. Throws InputError if the
// file cannot be opened or is not a session log.
std::vector<SessionFrames> ReadSessionLog(const std::filesystem::path& path,
                                          SessionReadReport* report = nullptr);

}  // namespace silnet
