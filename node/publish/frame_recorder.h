#pragma once
// --record: the node's streams written to its camera's session log (shared/io/session_log.h),
// crash-safe. When writing fails (a full disk), records wait in memory — up to a limit, then
// the oldest are counted as lost — and are written when writing works again; the failure is
// reported through counters() and the node's status. Thread-safe.

#include <deque>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "shared/io/session_log.h"
#include "shared/record/record_log.h"

namespace silnet::node {

// What the recorder did.
struct RecorderCounters {
  uint64_t written = 0;
  uint64_t pending = 0;    // waiting in memory for the disk
  uint64_t lost = 0;       // dropped because the memory limit was reached
  uint64_t failures = 0;   // failed write attempts
  std::string last_error;  // empty while healthy
};

// Appends records to a camera's session log.
class FrameRecorder {
 public:
  FrameRecorder(std::filesystem::path dir, std::string camera_id, size_t max_pending = 100000);

  // Creates the folder and opens (or reopens, recovering a torn tail) the log; throws
  // InputError naming the path if that fails.
  void Open();
  // Queues a record and writes everything queued that the disk accepts.
  void Add(SessionRecordType type, std::vector<uint8_t> payload);
  // Writes what is queued and flushes to the device.
  void Flush();
  RecorderCounters counters() const;
  const std::filesystem::path& path() const { return path_; }

 private:
  void Drain();

  std::filesystem::path dir_;
  std::filesystem::path path_;
  size_t max_pending_;
  mutable std::mutex mutex_;
  RecordLogWriter writer_;
  std::deque<std::pair<SessionRecordType, std::vector<uint8_t>>> pending_;
  RecorderCounters counters_;
};

}  // namespace silnet::node
