#include "node/publish/frame_recorder.h"

#include <spdlog/spdlog.h>

#include "shared/util/check.h"

namespace silnet::node {

FrameRecorder::FrameRecorder(std::filesystem::path dir, std::string camera_id, size_t max_pending)
    : dir_(std::move(dir)), path_(SessionLogPath(dir_, camera_id)), max_pending_(max_pending) {}

void FrameRecorder::Open() {
  std::error_code error;
  std::filesystem::create_directories(dir_, error);
  if (error)
    throw InputError("cannot create recording folder " + dir_.string() + ": " + error.message());
  const RecordLogStatus status = writer_.Open(path_, kSessionLogStreamKind);
  if (!status.ok())
    throw InputError("cannot record to " + path_.string() + ": " + status.message());
  const RecordLogRecovery& recovery = writer_.recovery();
  if (recovery.tail_truncated) {
    spdlog::warn("{}: cut {} bytes of a torn tail after {} records ({})", path_.string(),
                 recovery.bytes_truncated, recovery.records, recovery.tail_reason);
  }
}

void FrameRecorder::Add(SessionRecordType type, std::vector<uint8_t> payload) {
  std::lock_guard lock(mutex_);
  pending_.emplace_back(type, std::move(payload));
  if (pending_.size() > max_pending_) {
    pending_.pop_front();
    ++counters_.lost;
  }
  Drain();
}

void FrameRecorder::Drain() {
  while (!pending_.empty()) {
    const auto& [type, payload] = pending_.front();
    const RecordLogStatus status = writer_.Append(static_cast<uint16_t>(type), payload);
    if (!status.ok()) {
      if (counters_.last_error.empty()) spdlog::error("recording paused: {}", status.message());
      ++counters_.failures;
      counters_.last_error = status.message();
      break;
    }
    if (!counters_.last_error.empty()) {
      spdlog::info("recording resumed on {}", path_.string());
      counters_.last_error.clear();
    }
    ++counters_.written;
    pending_.pop_front();
  }
  counters_.pending = pending_.size();
}

void FrameRecorder::Flush() {
  std::lock_guard lock(mutex_);
  Drain();
  const RecordLogStatus status = writer_.Flush();
  if (!status.ok()) {
    ++counters_.failures;
    counters_.last_error = status.message();
  }
}

RecorderCounters FrameRecorder::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

}  // namespace silnet::node
