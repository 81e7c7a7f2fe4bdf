// silnet-aggregator: the aggregator's jobs as subcommands.
//   ingest   subscribe to the nodes, store every session durably, request missing frames
//   pairs    every camera pair's epipolar geometry and time offset from the silhouettes

#include <signal.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdio>
#include <thread>

#include "aggregator/ingest/ingest_service.h"
#include "aggregator/pairwise/pairwise_job.h"
#include "shared/dds/dds_error.h"
#include "shared/util/check.h"
#include "shared/util/log.h"

namespace {

using silnet::InputError;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};

// SIGINT/SIGTERM are taken by a watcher thread; other threads have them blocked.
void WatchSignals() {
  static sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([] {
    int received = 0;
    sigwait(&signals, &received);
    g_stop = true;
  }).detach();
}

void PrintStatus(const std::vector<silnet::aggregator::CameraIngestStatus>& cameras) {
  for (const auto& c : cameras) {
    std::fprintf(
        stderr,
        "  %-8s session %u: %llu frames held (%llu..%llu), %llu missing, %llu duplicates, "
        "%llu malformed, %llu re-send requests; node %s %.1f fps\n",
        c.camera_id.c_str(), c.session, static_cast<unsigned long long>(c.frames_held),
        static_cast<unsigned long long>(c.first_frame),
        static_cast<unsigned long long>(c.last_frame), static_cast<unsigned long long>(c.missing),
        static_cast<unsigned long long>(c.duplicates), static_cast<unsigned long long>(c.malformed),
        static_cast<unsigned long long>(c.resend_requests), c.node_state.c_str(), c.node_fps);
  }
}

struct IngestArgs {
  std::string out;
  double idle_exit_s = 0.0;
  double status_every_s = 5.0;
  int domain = -1;
  bool loopback = false;
};

int RunIngest(const IngestArgs& args) {
  silnet::aggregator::IngestOptions options;
  options.store_dir = std::filesystem::path(args.out) / "sessions";
  options.domain = silnet::dds::DomainConfig::FromEnvironment();
  if (args.domain >= 0) options.domain.domain_id = static_cast<uint32_t>(args.domain);
  if (args.loopback) options.domain.loopback = true;
  silnet::aggregator::IngestService ingest(options);
  ingest.Open();
  spdlog::info("ingesting into {} ({})", options.store_dir.string(), options.domain.Describe());
  auto last_activity = Clock::now();
  auto next_status = Clock::now() + std::chrono::duration<double>(args.status_every_s);
  while (!g_stop) {
    if (ingest.Poll(std::chrono::milliseconds(100)) > 0) last_activity = Clock::now();
    const auto now = Clock::now();
    if (args.status_every_s > 0 && now >= next_status) {
      next_status = now + std::chrono::duration<double>(args.status_every_s);
      PrintStatus(ingest.Status());
    }
    const silnet::aggregator::IngestTotals totals = ingest.Totals();
    if (args.idle_exit_s > 0 && totals.received > 0 && totals.missing == 0 &&
        totals.contours_overdue == 0 &&
        now - last_activity > std::chrono::duration<double>(args.idle_exit_s)) {
      spdlog::info("no samples for {} s and nothing missing: done", args.idle_exit_s);
      break;
    }
  }
  ingest.Flush();
  ingest.WriteSummary(std::filesystem::path(args.out) / "ingest_summary.yaml");
  PrintStatus(ingest.Status());
  const silnet::aggregator::IngestTotals t = ingest.Totals();
  std::printf(
      "ingest: %llu samples received, %llu frames held, %llu missing, %llu duplicates, %llu "
      "malformed, "
      "%llu re-send requests, %llu contours overdue, %llu lost and %llu rejected by DDS\n",
      static_cast<unsigned long long>(t.received), static_cast<unsigned long long>(t.stored),
      static_cast<unsigned long long>(t.missing), static_cast<unsigned long long>(t.duplicates),
      static_cast<unsigned long long>(t.malformed),
      static_cast<unsigned long long>(t.resend_requests),
      static_cast<unsigned long long>(t.contours_overdue),
      static_cast<unsigned long long>(t.dds_samples_lost),
      static_cast<unsigned long long>(t.dds_samples_rejected));
  return 0;
}

// Cancels `progress` when SIGINT/SIGTERM arrives, while the job runs.
class CancelOnSignal {
 public:
  explicit CancelOnSignal(silnet::Progress* progress)
      : watcher_([this, progress] {
          while (!done_ && !g_stop)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
          if (g_stop) progress->Cancel();
        }) {}
  ~CancelOnSignal() {
    done_ = true;
    watcher_.join();
  }

 private:
  std::atomic<bool> done_{false};
  std::thread watcher_;
};

struct PairsArgs {
  std::string input, out, overlays = "ok";
  bool synchronized = false, use_timestamps = false;
  double max_offset = 35.0, timestamp_sigma = 2.0;
  int threads = 0, max_frames = 0;
  uint64_t seed = 1;
  size_t iterations = 1000000;
};

int RunPairs(const PairsArgs& args) {
  silnet::aggregator::PairsJobConfig config;
  config.input = args.input;
  config.output = args.out;
  config.max_frames = args.max_frames;
  config.options.threads = args.threads;
  config.options.use_timestamps = args.use_timestamps;
  config.options.timestamp_sigma = args.timestamp_sigma;
  config.options.pair.synchronized = args.synchronized;
  config.options.pair.offset_min = -args.max_offset;
  config.options.pair.offset_max = args.max_offset;
  config.options.pair.seed = args.seed;
  config.options.pair.max_iterations = args.iterations;
  if (args.overlays == "none") {
    config.overlays = silnet::aggregator::OverlaySelection::kNone;
  } else if (args.overlays == "all") {
    config.overlays = silnet::aggregator::OverlaySelection::kAll;
  } else if (args.overlays != "ok") {
    throw InputError("--overlays must be none, ok or all");
  }
  if (const std::string reason = config.options.pair.Validate(); !reason.empty())
    throw InputError(reason);
  silnet::Progress progress("pairs", 0, silnet::ConsoleProgressPrinter(), std::chrono::seconds(2));
  CancelOnSignal cancel(&progress);
  const auto result = silnet::aggregator::RunPairsJob(config, &progress);
  if (progress.cancelled()) {
    std::fprintf(stderr, "silnet-aggregator: cancelled\n");
    return 130;
  }
  std::printf("pairs: %zu of %zu ok in %.1f s -> %s/pairs.yaml\n", result.ok(), result.pairs.size(),
              result.seconds, args.out.c_str());
  for (const auto& p : result.pairs) {
    std::printf("  %s-%s  %-10s offset %+9.3f +- %.3f  %5zu inliers  %.2f px  %s\n",
                p.camera_i.c_str(), p.camera_j.c_str(), silnet::aggregator::ToString(p.status),
                p.offset, p.offset_sigma, p.inliers, p.residual_rms, p.reason.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"silnet-aggregator: calibrate and synchronise camera networks from silhouettes"};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();

  IngestArgs ingest;
  CLI::App* ingest_cmd =
      app.add_subcommand("ingest", "subscribe to the nodes and store every session");
  ingest_cmd
      ->add_option("-o,--out", ingest.out, "output folder (sessions/ and ingest_summary.yaml)")
      ->required();
  ingest_cmd
      ->add_option("--idle-exit", ingest.idle_exit_s,
                   "exit after this many seconds without samples once nothing is missing")
      ->capture_default_str();
  ingest_cmd->add_option("--status-every", ingest.status_every_s, "seconds between status lines")
      ->capture_default_str();
  ingest_cmd->add_option("--domain", ingest.domain,
                         "DDS domain id (default: SILNET_DDS_DOMAIN or 0)");
  ingest_cmd->add_flag("--loopback", ingest.loopback, "DDS on 127.0.0.1 only");

  PairsArgs pairs;
  CLI::App* pairs_cmd =
      app.add_subcommand("pairs", "every camera pair's epipolar geometry and time offset");
  pairs_cmd
      ->add_option(
          "input", pairs.input,
          "session store, node recording, or dataset folder (masks/ or frames/ per camera)")
      ->required();
  pairs_cmd->add_option("-o,--out", pairs.out, "output folder")->required();
  pairs_cmd->add_flag("--synchronized", pairs.synchronized, "the cameras share a clock (offset 0)");
  pairs_cmd
      ->add_option("--max-offset", pairs.max_offset, "search offsets within +-this many frames")
      ->capture_default_str();
  pairs_cmd->add_flag("--use-timestamps", pairs.use_timestamps,
                      "narrow the offset search with capture timestamps");
  pairs_cmd
      ->add_option("--timestamp-sigma", pairs.timestamp_sigma, "frames the timestamps may be off")
      ->capture_default_str();
  pairs_cmd->add_option("--threads", pairs.threads, "pairs estimated at once (0 = all cores)")
      ->capture_default_str();
  pairs_cmd->add_option("--max-frames", pairs.max_frames, "use at most this many frames (0 = all)");
  pairs_cmd->add_option("--seed", pairs.seed, "random seed (same seed, same result)")
      ->capture_default_str();
  pairs_cmd->add_option("--iterations", pairs.iterations, "RANSAC iterations per pair at most")
      ->capture_default_str();
  pairs_cmd->add_option("--overlays", pairs.overlays, "PNG overlays for none, ok or all pairs")
      ->capture_default_str();

  CLI11_PARSE(app, argc, argv);
  WatchSignals();
  try {
    silnet::ConfigureLogging("silnet-aggregator", log_level);
    if (ingest_cmd->parsed()) return RunIngest(ingest);
    if (pairs_cmd->parsed()) return RunPairs(pairs);
  } catch (const InputError& e) {
    std::fprintf(stderr, "silnet-aggregator: %s\n", e.what());
    return 2;
  } catch (const silnet::dds::DdsError& e) {
    std::fprintf(stderr, "silnet-aggregator: DDS failed: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "silnet-aggregator: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
