#pragma once
// Controlling a running live job from the command line: the job keeps its process id in
// OUT/live.pid while it runs; `silnet-aggregator recalibrate OUT` sends it SIGHUP (the job
// recalibrates on the newest frames), `silnet-aggregator status OUT` prints what the job's
// status files say: every node's liveness, rate and losses (session/ingest_summary.yaml,
// rewritten every few seconds) and every camera's epipolar residuals against the
// calibration in use (camera_motion.yaml); `silnet-aggregator stills OUT` asks it for stills
// (OUT/stills_request.yaml and SIGUSR1; the job answers in OUT/stills_answer.yaml).

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

// A request for stills to the live job in a folder: the job takes them with the calibration
// it uses into OUT/stills (replacing earlier ones) and adds the model to its report.
struct StillsRequest {
  std::string id;      // unique per request (the asking process's id and clock)
  double at_s = -1.0;  // reference instant in seconds; negative: each node's next frame
  bool stereo = true;  // build the stereo model
  // Of the empty scene instead: every node keeps its own to segment its later stills; they
  // are written into OUT/backgrounds.
  bool background = false;
};

// Where the live job is with a stills request.
struct StillsAnswer {
  std::string id;     // the request's id
  std::string state;  // "waiting" (for a calibration or earlier stills), "running", "done" or
                      // "failed"
  std::string text;   // what came of it, for the user (lines ending in '\n')
};

// Asks the live job running in `output` for stills and returns its process id. Throws
// InputError naming the folder if no live job runs there, or if the request cannot be written.
int RequestStills(const std::filesystem::path& output, const StillsRequest& request);

// The live job's side: the request written into `output`, removed from there (nullopt if none
// or unreadable: an unreadable request is removed too, and reported in the log).
std::optional<StillsRequest> TakeStillsRequest(const std::filesystem::path& output);

// Writes the answer to a request (replacing the file at once, so a reader never sees half).
void WriteStillsAnswer(const std::filesystem::path& output, const StillsAnswer& answer);

// The live job's last answer in `output`, nullopt if there is none (yet).
std::optional<StillsAnswer> ReadStillsAnswer(const std::filesystem::path& output);

// A readable status of the live job in `output`. Throws InputError if the folder holds no
// live job's status.
std::string LiveStatusText(const std::filesystem::path& output);

}  // namespace silnet::aggregator
