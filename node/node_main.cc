// silnet-node: the program on each camera host. Captures frames, segments the moving
// subject, reduces each silhouette to its convex hull and tangent table (and contour) and
// publishes them over DDS. Options may also come from a TOML/INI file (--config); see
// silnet-node --help.

#include <signal.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "node/camera_node.h"
#include "node/capture/source_factory.h"
#include "shared/dds/dds_error.h"
#include "shared/io/session_log.h"
#include "shared/io/session_log_reader.h"
#include "shared/util/log.h"

namespace {

using silnet::InputError;

// Splits "name=value".
std::pair<std::string, std::string> SplitSetting(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set wants name=value, not '" + text + "'");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

}  // namespace

namespace {

// The start time in seconds, or one past the newest session of the node's recording if that
// is not older: a node restarted within a second never reuses a session id.
uint32_t DefaultSession(const std::string& record_dir, const std::string& camera_id) {
  auto session = static_cast<uint32_t>(std::chrono::duration_cast<std::chrono::seconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count());
  if (record_dir.empty()) return session;
  const std::filesystem::path log = silnet::SessionLogPath(record_dir, camera_id);
  if (!std::filesystem::exists(log)) return session;
  try {
    const auto sessions = silnet::ReadSessionLog(log);
    if (!sessions.empty()) session = std::max(session, sessions.back().session + 1);
  } catch (const silnet::InputError&) {
    // An unreadable recording is reported when the recorder opens it.
  }
  return session;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"silnet-node: camera capture, silhouette segmentation and publishing over DDS"};
  app.set_config("--config", "", "read options from a TOML/INI file");
  silnet::node::CameraNodeOptions options;
  silnet::node::SourceOptions source_options;
  std::string camera_id, source_text, method = "median", log_level = "info", record_dir;
  std::vector<std::string> settings;
  int domain = -1;
  bool loopback = false;
  std::string dds_tag;
  double linger_s = 5.0;
  int64_t session = 0;
  app.add_option("--camera-id", camera_id, "this camera's id (at most 31 characters)")->required();
  app.add_option("--source", source_text,
                 "capture source: v4l2:/dev/videoN, libcamera:ID, video:FILE, images:DIR, "
                 "masks:DIR, sim:DATASET/CAMERA, sim-masks:DATASET/CAMERA")
      ->required();
  app.add_option("--width", source_options.width, "frame width to ask the device for")
      ->capture_default_str();
  app.add_option("--height", source_options.height, "frame height to ask the device for")
      ->capture_default_str();
  app.add_option("--fps", source_options.fps, "frame rate (devices; files when --real-time)")
      ->capture_default_str();
  app.add_option("--pixel-format", source_options.pixel_format, "v4l2: yuyv, mjpeg or auto")
      ->capture_default_str();
  app.add_flag("--video-stills", source_options.video_stills,
               "v4l2, libcamera: stills at the video size, not from the camera's largest size");
  app.add_flag("--real-time", source_options.real_time, "release file frames at their due time");
  app.add_option("--start-at", source_options.start_ns,
                 "pacing: CLOCK_REALTIME ns of reference time 0 (0 = now); share it between "
                 "nodes replaying one simulated network");
  app.add_option("--speed", source_options.speed, "sim: replay speed factor")
      ->capture_default_str();
  app.add_option("--segmentation", method, "median, mog2, knn or mask")->capture_default_str();
  app.add_option("--set", settings, "segmentation setting name=value (repeatable)");
  app.add_option("--contour-every", options.processing.contour_every,
                 "publish the full contour every N frames (0 = never)")
      ->capture_default_str();
  app.add_option("--record", record_dir, "record the streams to a crash-safe log in this folder");
  app.add_option("--history", options.history_frames, "frames kept for resend requests")
      ->capture_default_str();
  app.add_option("--dds-history", options.qos.frame_history,
                 "frames a late subscriber receives from the DDS writer's history")
      ->capture_default_str();
  app.add_option("--linger", linger_s, "seconds to stay after a finite source ends")
      ->capture_default_str();
  app.add_flag("--stopped", options.start_stopped, "wait for a start command before publishing");
  app.add_flag("--lossless", options.lossless,
               "replays: capture waits for segmentation instead of dropping frames when the "
               "machine is busy (never for a live camera)");
  size_t still_chunk_kb = options.still_chunk_bytes / 1024;
  app.add_option("--still-chunk-kb", still_chunk_kb, "stills travel in chunks of this many KiB")
      ->capture_default_str()
      ->check(CLI::Range(1, 16384));
  app.add_option("--test-drop-still-chunk", options.still_faults.drop_chunk,
                 "tests: leave this chunk of every still part out of its first sending");
  app.add_option("--test-corrupt-still-chunk", options.still_faults.corrupt_chunk,
                 "tests: flip a byte of this chunk of every still part in its first sending");
  app.add_option("--session", session, "session number (default: start time in seconds)");
  app.add_option("--domain", domain, "DDS domain id (default: SILNET_DDS_DOMAIN or 0)");
  app.add_flag("--loopback", loopback, "DDS on 127.0.0.1 only");
  app.add_option("--dds-tag", dds_tag, "DDS discovery tag");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  // A file-size limit fails the recorder's write with EFBIG (reported, recording pauses)
  // instead of killing the node.
  signal(SIGXFSZ, SIG_IGN);
  // SIGINT/SIGTERM are taken by a watcher thread; every other thread has them blocked.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::atomic<bool> stop{false};
  std::thread watcher([&] {
    int received = 0;
    sigwait(&signals, &received);
    stop = true;
  });
  watcher.detach();

  try {
    silnet::ConfigureLogging("silnet-node", log_level);
    options.processing.camera_id = camera_id;
    options.processing.session =
        session > 0 ? static_cast<uint32_t>(session) : DefaultSession(record_dir, camera_id);
    const silnet::node::SourceDescription description =
        silnet::node::ParseSourceDescription(source_text);
    options.processing.segmentation.method = description.masks()
                                                 ? silnet::node::SegmentationMethod::kMaskInput
                                                 : silnet::node::ParseSegmentationMethod(method);
    for (const std::string& setting : settings) {
      const auto [name, value] = SplitSetting(setting);
      std::string error;
      if (!options.processing.segmentation.Set(name, value, &error)) throw InputError(error);
    }
    options.record_dir = record_dir;
    options.still_chunk_bytes = still_chunk_kb * 1024;
    options.linger = std::chrono::milliseconds(static_cast<int64_t>(linger_s * 1000));
    options.domain = silnet::dds::DomainConfig::FromEnvironment();
    if (domain >= 0) options.domain.domain_id = static_cast<uint32_t>(domain);
    if (loopback) options.domain.loopback = true;
    if (!dds_tag.empty()) options.domain.discovery_tag = dds_tag;
    if (const std::string reason = options.Validate(); !reason.empty()) throw InputError(reason);
    silnet::node::CameraNode node(options,
                                  silnet::node::MakeCaptureSource(description, source_options));
    node.Run(stop);
  } catch (const InputError& e) {
    spdlog::error("{}", e.what());
    std::fprintf(stderr, "silnet-node: %s\n", e.what());
    return 2;
  } catch (const silnet::dds::DdsError& e) {
    std::fprintf(stderr, "silnet-node: DDS failed: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "silnet-node: internal error: %s\n", e.what());
    return 1;
  }
  spdlog::default_logger()->flush();
  return 0;
}
