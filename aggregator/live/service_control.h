#pragma once
// Controlling a running live job from the command line: the job keeps its process id in
// OUT/live.pid while it runs; `silnet-aggregator recalibrate OUT` sends it SIGHUP (the job
// recalibrates on the newest frames), `silnet-aggregator status OUT` prints what the job's
// status files say: every node's liveness, rate and losses (session/ingest_summary.yaml,
// rewritten every few seconds) and every camera's epipolar residuals against the
// calibration in use (camera_motion.yaml).

#include <filesystem>
#include <optional>
#include <string>

namespace silnet::aggregator {

// OUT/live.pid for as long as the object lives (written at construction, removed at
// destruction). Throws InputError if another live job still runs in the same folder or the
// file cannot be written.
class LivePidFile {
 public:
  explicit LivePidFile(const std::filesystem::path& output);
  ~LivePidFile();
  LivePidFile(const LivePidFile&) = delete;
  LivePidFile& operator=(const LivePidFile&) = delete;

 private:
  std::filesystem::path path_;
};

// The process id of the live job running in `output`, or nullopt if none runs there (no pid
// file, or its process has gone).
std::optional<int> RunningLiveJob(const std::filesystem::path& output);

// Asks the live job running in `output` to recalibrate and returns its process id. Throws
// InputError naming the folder if no live job runs there.
int RequestRecalibration(const std::filesystem::path& output);

// A readable status of the live job in `output`. Throws InputError if the folder holds no
// live job's status.
std::string LiveStatusText(const std::filesystem::path& output);

}  // namespace silnet::aggregator
