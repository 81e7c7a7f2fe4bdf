#pragma once
// What the aggregator's subcommands share: signal handling (SIGINT/SIGTERM stop a running
// job cleanly), the pairwise estimation options, which `pairs` and `calibrate` both take, and
// the lens distortion setting of `calibrate` and `live`.

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include "aggregator/calibration/network_calibration.h"
#include "aggregator/pairwise/pairwise_job.h"
#include "shared/util/progress.h"

namespace silnet::aggregator::cli {

// Adds `--distortion` (auto, none, k1, k1k2; default auto) to `command`, into `setting`.
void AddDistortionOption(CLI::App* command, std::string* setting);
// Applies a `--distortion` setting to `options` (auto: radial terms looked for, see
// CalibrationOptions::detect_distortion); throws InputError for an unknown one.
void ApplyDistortionSetting(const std::string& setting, CalibrationOptions* options);

// Routes SIGINT, SIGTERM, SIGHUP and SIGUSR1 to a watcher thread (other threads have them blocked)
// and ignores SIGXFSZ (a file-size limit becomes a reported write error); call once before starting
// threads.
void WatchSignals();
// True once SIGINT or SIGTERM arrived.
bool StopRequested();
// True once per SIGHUP received since the last call: the service's "recalibrate" command.
bool TakeRecalibrationRequest();
// True once per SIGUSR1 received since the last call: the service's "stills" command (its
// request waits in the job's folder, live/service_control.h).
bool TakeStillsSignal();

// Cancels `progress` when SIGINT/SIGTERM arrives, while the job runs.
class CancelOnSignal {
 public:
  explicit CancelOnSignal(Progress* progress);
  ~CancelOnSignal();
  CancelOnSignal(const CancelOnSignal&) = delete;
  CancelOnSignal& operator=(const CancelOnSignal&) = delete;

 private:
  std::atomic<bool> done_{false};
  std::thread watcher_;
};

// Runs `job(Progress*)` with console progress under `name`, cancelled by SIGINT/SIGTERM.
// Returns the job's result, or nullopt (after saying so on stderr) if it was cancelled.
template <typename Job>
auto RunWithProgress(const std::string& name, Job&& job)
    -> std::optional<decltype(job(static_cast<Progress*>(nullptr)))> {
  Progress progress(name, 0, ConsoleProgressPrinter(), std::chrono::seconds(2));
  CancelOnSignal cancel(&progress);
  auto result = job(&progress);
  if (progress.cancelled()) {
    std::fprintf(stderr, "silnet-aggregator: cancelled\n");
    return std::nullopt;
  }
  return result;
}

// Command-line form of the pairwise options.
struct PairwiseArgs {
  bool synchronized = false, use_timestamps = false;
  double max_offset = 35.0, timestamp_sigma = 2.0, local_fit_px = 2.0;
  int threads = 0;
  uint64_t seed = 1;
  size_t iterations = 1000000;
  std::string mask_video;   // each camera folder's mask video (dataset input)
  std::string frame_video;  // each camera folder's colour video (dataset input)

  // Adds --synchronized, --max-offset, --use-timestamps, --timestamp-sigma, --threads, --seed,
  // --iterations, --local-fit, --mask-video and --video to `command`.
  void AddTo(CLI::App* command);
  // The job options; throws InputError for invalid values.
  PairwiseJobOptions Options() const;
};

}  // namespace silnet::aggregator::cli
