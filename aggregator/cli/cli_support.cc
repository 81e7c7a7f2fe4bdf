#include "aggregator/cli/cli_support.h"

#include <signal.h>

#include <chrono>

#include "shared/util/check.h"

namespace silnet::aggregator::cli {

void AddDistortionOption(CLI::App* command, std::string* setting) {
  command
      ->add_option("--distortion", *setting,
                   "radial distortion to estimate: none, k1, k1k2, or auto (k1 and k2 when they "
                   "fit the silhouettes clearly better; not where the intrinsics are given)")
      ->capture_default_str();
}

void ApplyDistortionSetting(const std::string& setting, CalibrationOptions* options) {
  options->detect_distortion = setting == "auto";
  if (setting == "none" || setting == "auto") {
    options->intrinsics.radial_terms = 0;
  } else if (setting == "k1") {
    options->intrinsics.radial_terms = 1;
  } else if (setting == "k1k2") {
    options->intrinsics.radial_terms = 2;
  } else {
    throw InputError("--distortion must be auto, none, k1 or k1k2");
  }
}

namespace {

std::atomic<bool> g_stop{false};
std::atomic<bool> g_recalibrate{false};
std::atomic<bool> g_stills{false};

}  // namespace

void WatchSignals() {
  // A file-size limit (RLIMIT_FSIZE) then fails the write with EFBIG, which the session
  // store reports and recovers from like a full disk, instead of killing the process.
  signal(SIGXFSZ, SIG_IGN);
  static sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGHUP);
  sigaddset(&signals, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([] {
    int received = 0;
    while (sigwait(&signals, &received) == 0) {
      if (received == SIGHUP) {
        g_recalibrate = true;
      } else if (received == SIGUSR1) {
        g_stills = true;
      } else {
        break;
      }
    }
    g_stop = true;
  }).detach();
}

bool StopRequested() {
  return g_stop.load();
}

bool TakeRecalibrationRequest() {
  return g_recalibrate.exchange(false);
}

bool TakeStillsSignal() {
  return g_stills.exchange(false);
}

CancelOnSignal::CancelOnSignal(Progress* progress)
    : watcher_([this, progress] {
        while (!done_ && !g_stop)
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (g_stop) progress->Cancel();
      }) {}

CancelOnSignal::~CancelOnSignal() {
  done_ = true;
  watcher_.join();
}

void PairwiseArgs::AddTo(CLI::App* command) {
  command->add_flag("--synchronized", synchronized, "the cameras share a clock (offset 0)");
  command->add_option("--max-offset", max_offset, "search offsets within +-this many frames")
      ->capture_default_str();
  command->add_flag("--use-timestamps", use_timestamps,
                    "narrow the offset search with capture timestamps");
  command->add_option("--timestamp-sigma", timestamp_sigma, "frames the timestamps may be off")
      ->capture_default_str();
  command->add_option("--threads", threads, "pairs estimated at once (0 = all cores)")
      ->capture_default_str();
  command->add_option("--seed", seed, "random seed (same seed, same result)")
      ->capture_default_str();
  command->add_option("--iterations", iterations, "RANSAC iterations per pair at most")
      ->capture_default_str();
  command
      ->add_option("--local-fit", local_fit_px,
                   "pixels within which a hypothesis's local fit must explain its frontier "
                   "points (3 suits silhouettes with lens distortion; calibrate raises it to 3 "
                   "itself unless --intrinsics or --distortion none)")
      ->capture_default_str();
  command->add_option("--mask-video", mask_video,
                      "read each camera's silhouettes from this video file in its folder "
                      "(e.g. foreground.avi; grey above 128 is silhouette)");
  command->add_option("--video", frame_video,
                      "read each camera's colour video of this name in its folder and segment it "
                      "with the node's pipeline");
}

PairwiseJobOptions PairwiseArgs::Options() const {
  PairwiseJobOptions options;
  options.threads = threads;
  options.use_timestamps = use_timestamps;
  options.timestamp_sigma = timestamp_sigma;
  options.pair.synchronized = synchronized;
  options.pair.offset_min = -max_offset;
  options.pair.offset_max = max_offset;
  options.pair.seed = seed;
  options.pair.max_iterations = iterations;
  options.pair.local_fit_px = local_fit_px;
  if (const std::string reason = options.pair.Validate(); !reason.empty()) throw InputError(reason);
  return options;
}

}  // namespace silnet::aggregator::cli
