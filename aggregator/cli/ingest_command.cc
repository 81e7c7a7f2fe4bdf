// silnet-aggregator ingest: subscribe to the nodes, store every session durably, request
// missing frames; status lines while it runs, a summary at the end.

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "aggregator/ingest/ingest_service.h"

namespace silnet::aggregator::cli {
namespace {

using Clock = std::chrono::steady_clock;

struct IngestArgs {
  std::string out;
  double idle_exit_s = 0.0;
  double give_up_s = 60.0;
  double status_every_s = 5.0;
  double stall_after_s = 3.0;
  int domain = -1;
  bool loopback = false;
};

void PrintStatus(const std::vector<CameraIngestStatus>& cameras) {
  for (const auto& c : cameras) {
    std::fprintf(
        stderr,
        "  %-8s session %u: %llu frames held (%llu..%llu), %llu missing, %llu duplicates, "
        "%llu malformed, %llu re-send requests, %llu store failures; node %s %.1f fps, %llu "
        "dropped, %llu flagged%s%s\n",
        c.camera_id.c_str(), c.session, static_cast<unsigned long long>(c.frames_held),
        static_cast<unsigned long long>(c.first_frame),
        static_cast<unsigned long long>(c.last_frame), static_cast<unsigned long long>(c.missing),
        static_cast<unsigned long long>(c.duplicates), static_cast<unsigned long long>(c.malformed),
        static_cast<unsigned long long>(c.resend_requests),
        static_cast<unsigned long long>(c.store_failures), c.node_state.c_str(), c.node_fps,
        static_cast<unsigned long long>(c.node_dropped),
        static_cast<unsigned long long>(c.node_flagged), c.node_alive ? "" : ", not heard from",
        c.stalled ? "  STALLED" : "");
  }
}

int RunIngest(const IngestArgs& args) {
  IngestOptions options;
  options.store_dir = std::filesystem::path(args.out) / "sessions";
  options.domain = dds::DomainConfig::FromEnvironment();
  if (args.domain >= 0) options.domain.domain_id = static_cast<uint32_t>(args.domain);
  if (args.loopback) options.domain.loopback = true;
  options.stall_after = std::chrono::milliseconds(static_cast<int64_t>(args.stall_after_s * 1000));
  IngestService ingest(options);
  ingest.Open();
  spdlog::info("ingesting into {} ({})", options.store_dir.string(), options.domain.Describe());
  auto last_activity = Clock::now();
  auto next_status = Clock::now() + std::chrono::duration<double>(args.status_every_s);
  while (!StopRequested()) {
    if (ingest.Poll(std::chrono::milliseconds(100)) > 0) last_activity = Clock::now();
    const auto now = Clock::now();
    if (args.status_every_s > 0 && now >= next_status) {
      next_status = now + std::chrono::duration<double>(args.status_every_s);
      PrintStatus(ingest.Status());
      // The summary doubles as a status file other tools can read while ingest runs.
      ingest.WriteSummary(std::filesystem::path(args.out) / "ingest_summary.yaml");
    }
    const IngestTotals totals = ingest.Totals();
    const double idle = std::chrono::duration<double>(now - last_activity).count();
    if (args.idle_exit_s <= 0 || totals.received == 0 || idle <= args.idle_exit_s) continue;
    if (totals.missing == 0 && totals.contours_overdue == 0 && totals.cameras_stalled == 0) {
      spdlog::info("no samples for {} s and nothing missing: done", args.idle_exit_s);
      break;
    }
    if (idle > std::max(args.idle_exit_s, args.give_up_s)) {
      spdlog::warn(
          "no samples for {:.0f} s: giving up on {} missing frames, {} overdue contours and {} "
          "stalled cameras",
          idle, totals.missing, totals.contours_overdue, totals.cameras_stalled);
      break;
    }
  }
  ingest.Flush();
  ingest.WriteSummary(std::filesystem::path(args.out) / "ingest_summary.yaml");
  PrintStatus(ingest.Status());
  const IngestTotals t = ingest.Totals();
  std::printf(
      "ingest: %llu samples received, %llu frames held, %llu missing, %llu duplicates, %llu "
      "malformed, %llu re-send requests, %llu contours overdue, %llu lost and %llu rejected by "
      "DDS, %llu store failures, %llu stalls\n",
      static_cast<unsigned long long>(t.received), static_cast<unsigned long long>(t.stored),
      static_cast<unsigned long long>(t.missing), static_cast<unsigned long long>(t.duplicates),
      static_cast<unsigned long long>(t.malformed),
      static_cast<unsigned long long>(t.resend_requests),
      static_cast<unsigned long long>(t.contours_overdue),
      static_cast<unsigned long long>(t.dds_samples_lost),
      static_cast<unsigned long long>(t.dds_samples_rejected),
      static_cast<unsigned long long>(t.store_failures), static_cast<unsigned long long>(t.stalls));
  return 0;
}

}  // namespace

Command AddIngestCommand(CLI::App& app) {
  auto args = std::make_shared<IngestArgs>();
  CLI::App* cmd = app.add_subcommand("ingest", "subscribe to the nodes and store every session");
  cmd->add_option("-o,--out", args->out, "output folder (sessions/ and ingest_summary.yaml)")
      ->required();
  cmd->add_option(
         "--idle-exit", args->idle_exit_s,
         "exit after this many seconds without samples once nothing is missing and no camera is "
         "stalled")
      ->capture_default_str();
  cmd->add_option("--give-up-after", args->give_up_s,
                  "with --idle-exit: exit after this many idle seconds even if frames are missing")
      ->capture_default_str();
  cmd->add_option("--status-every", args->status_every_s, "seconds between status lines")
      ->capture_default_str();
  cmd->add_option("--stall-after", args->stall_after_s,
                  "report a camera stalled after this many seconds without a frame")
      ->capture_default_str();
  cmd->add_option("--domain", args->domain, "DDS domain id (default: SILNET_DDS_DOMAIN or 0)");
  cmd->add_flag("--loopback", args->loopback, "DDS on 127.0.0.1 only");
  return {cmd, [args] { return RunIngest(*args); }};
}

}  // namespace silnet::aggregator::cli
