#include "aggregator/live/service_control.h"

#include <fmt/format.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>

#include "shared/io/replace_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

std::filesystem::path PidPath(const std::filesystem::path& output) {
  return output / "live.pid";
}

bool ProcessExists(int pid) {
  return pid > 0 && (kill(pid, 0) == 0 || errno == EPERM);
}

// Reads a status file; an empty FileStorage if it is missing or unreadable.
cv::FileStorage ReadStatus(const std::filesystem::path& path) {
  cv::FileStorage fs;
  if (!std::filesystem::exists(path)) return fs;
  try {
    fs.open(path.string(), cv::FileStorage::READ);
  } catch (const cv::Exception&) {
    fs.release();
  }
  return fs;
}

std::filesystem::path StillsRequestPath(const std::filesystem::path& output) {
  return output / "stills_request.yaml";
}

std::filesystem::path StillsAnswerPath(const std::filesystem::path& output) {
  return output / "stills_answer.yaml";
}

std::string NodesText(const cv::FileStorage& ingest) {
  std::string text =
      fmt::format("  {:<8} {:<6} {:<10} {:>6} {:>9} {:>8} {:>8} {:>7} {:>10}\n", "camera", "alive",
                  "state", "fps", "frames", "missing", "dropped", "stalls", "since last");
  for (const cv::FileNode& c : ingest["cameras"]) {
    text += fmt::format(
        "  {:<8} {:<6} {:<10} {:>6.1f} {:>9.0f} {:>8.0f} {:>8.0f} {:>7.0f} {:>8.1f} s\n",
        static_cast<std::string>(c["id"]), static_cast<int>(c["node_alive"]) ? "yes" : "NO",
        static_cast<std::string>(c["node_state"]), static_cast<double>(c["node_fps"]),
        static_cast<double>(c["frames_held"]), static_cast<double>(c["missing"]),
        static_cast<double>(c["node_dropped"]), static_cast<double>(c["stalls"]),
        static_cast<double>(c["seconds_since_last_frame"]));
  }
  return text;
}

std::string MotionText(const cv::FileStorage& motion) {
  std::string text =
      fmt::format("camera motion: {} checks of {} frames each, the last from frame {}\n",
                  static_cast<int>(motion["checks"]), static_cast<int>(motion["window_frames"]),
                  static_cast<int>(motion["last_window_first_frame"]));
  for (const cv::FileNode& c : motion["cameras"]) {
    const bool moved = static_cast<int>(c["moved"]) != 0;
    const bool suspect = static_cast<int>(c["suspect"]) != 0;
    text += fmt::format(
        "  {:<8} epipolar residual {:.2f} px (baseline {:.2f} px), {} of {} pairs "
        "jumped{}\n",
        static_cast<std::string>(c["id"]), static_cast<double>(c["residual_px"]),
        static_cast<double>(c["baseline_px"]), static_cast<int>(c["pairs_jumped"]),
        static_cast<int>(c["pairs_measured"]), moved ? ": MOVED" : (suspect ? ": suspect" : ""));
  }
  for (const cv::FileNode& m : motion["moves"]) {
    std::string what;
    if (static_cast<int>(m["reestimated"]) != 0) {
      what = fmt::format("re-estimated from frame {}, {:.3f} px rms",
                         static_cast<int>(m["reestimate_first_frame"]),
                         static_cast<double>(m["rms_px"]));
    } else {
      what = "not re-estimated yet";
      const std::string reason = static_cast<std::string>(m["reason"]);
      if (!reason.empty()) what += fmt::format(" ({})", reason);
    }
    text += fmt::format("  {} moved (seen by frame {}): {}\n", static_cast<std::string>(m["id"]),
                        static_cast<int>(m["detected_frame"]), what);
  }
  return text;
}

}  // namespace

LivePidFile::LivePidFile(const std::filesystem::path& output) : path_(PidPath(output)) {
  if (const auto running = RunningLiveJob(output); running && *running != getpid()) {
    throw InputError(
        fmt::format("a live job (process {}) already runs in {}", *running, output.string()));
  }
  std::filesystem::create_directories(output);
  std::ofstream out(path_);
  out << getpid() << "\n";
  if (!out) throw InputError("cannot write " + path_.string());
}

LivePidFile::~LivePidFile() {
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);
}

std::optional<int> RunningLiveJob(const std::filesystem::path& output) {
  std::ifstream in(PidPath(output));
  int pid = 0;
  if (!(in >> pid) || !ProcessExists(pid)) return std::nullopt;
  return pid;
}

int RequestRecalibration(const std::filesystem::path& output) {
  const std::optional<int> pid = RunningLiveJob(output);
  if (!pid) {
    throw InputError("no live job runs in " + output.string() +
                     " (start one with `silnet-aggregator live -o " + output.string() +
                     " --serve`)");
  }
  if (kill(*pid, SIGHUP) != 0)
    throw InputError(
        fmt::format("cannot signal the live job (process {}): {}", *pid, std::strerror(errno)));
  return *pid;
}

int RequestStills(const std::filesystem::path& output, const StillsRequest& request) {
  const std::optional<int> pid = RunningLiveJob(output);
  if (!pid) {
    throw InputError("no live job runs in " + output.string() +
                     " (give --calib to ask the nodes without one, or start one with "
                     "`silnet-aggregator live -o " +
                     output.string() + " --serve`)");
  }
  ReplaceYaml(StillsRequestPath(output), [&](cv::FileStorage& fs) {
    fs << "id" << request.id << "at_s" << request.at_s << "stereo"
       << static_cast<int>(request.stereo) << "background" << static_cast<int>(request.background);
  });
  if (kill(*pid, SIGUSR1) != 0)
    throw InputError(
        fmt::format("cannot signal the live job (process {}): {}", *pid, std::strerror(errno)));
  return *pid;
}

std::optional<StillsRequest> TakeStillsRequest(const std::filesystem::path& output) {
  const std::filesystem::path path = StillsRequestPath(output);
  const cv::FileStorage fs = ReadStatus(path);
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  if (!fs.isOpened()) return std::nullopt;
  StillsRequest request;
  request.id = static_cast<std::string>(fs["id"]);
  request.at_s = fs["at_s"].empty() ? -1.0 : static_cast<double>(fs["at_s"]);
  request.stereo = fs["stereo"].empty() || static_cast<int>(fs["stereo"]) != 0;
  request.background = !fs["background"].empty() && static_cast<int>(fs["background"]) != 0;
  if (request.id.empty() || !std::isfinite(request.at_s)) {
    spdlog::warn("live: ignoring an unreadable stills request in {}", path.string());
    return std::nullopt;
  }
  return request;
}

void WriteStillsAnswer(const std::filesystem::path& output, const StillsAnswer& answer) {
  ReplaceYaml(StillsAnswerPath(output), [&](cv::FileStorage& fs) {
    fs << "id" << answer.id << "state" << answer.state << "text" << answer.text;
  });
}

std::optional<StillsAnswer> ReadStillsAnswer(const std::filesystem::path& output) {
  const cv::FileStorage fs = ReadStatus(StillsAnswerPath(output));
  if (!fs.isOpened()) return std::nullopt;
  StillsAnswer answer;
  answer.id = static_cast<std::string>(fs["id"]);
  answer.state = static_cast<std::string>(fs["state"]);
  answer.text = static_cast<std::string>(fs["text"]);
  if (answer.id.empty()) return std::nullopt;
  return answer;
}

std::string LiveStatusText(const std::filesystem::path& output) {
  const cv::FileStorage ingest = ReadStatus(output / "session" / "ingest_summary.yaml");
  if (!ingest.isOpened())
    throw InputError(output.string() + " holds no live job's status (session/ingest_summary.yaml)");
  const std::optional<int> pid = RunningLiveJob(output);
  std::string text =
      pid ? fmt::format("live job running (process {}) in {}\n", *pid, output.string())
          : fmt::format("no live job running in {}; its last status:\n", output.string());
  text += "nodes:\n" + NodesText(ingest);
  const cv::FileStorage motion = ReadStatus(output / "camera_motion.yaml");
  if (motion.isOpened()) text += MotionText(motion);
  return text;
}

}  // namespace silnet::aggregator
