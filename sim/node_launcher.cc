#include "sim/node_launcher.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <map>

#include "shared/io/dataset_layout.h"
#include "shared/util/check.h"
#include "shared/util/realtime_clock.h"

extern char** environ;

namespace silnet::sim {
namespace {

// posix_spawn of `args` with stdout and stderr appended to `log`, signals unblocked.
pid_t Spawn(const std::vector<std::string>& args, const std::filesystem::path& log) {
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  std::vector<char*> argv;
  for (const std::string& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, args[0].c_str(), &files, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  SILNET_CHECK_MSG(error == 0, "cannot start " << args[0] << ": " << std::strerror(error));
  return pid;
}

}  // namespace

int RunNodes(const NodeLaunchOptions& options) {
  if (!std::filesystem::is_regular_file(options.node_binary))
    throw InputError("no silnet-node at " + options.node_binary.string());
  const DatasetLayout layout(options.dataset);
  const std::string kind = options.masks ? "masks" : "frames";
  std::vector<std::string> cameras;
  for (const std::string& id : layout.CameraIds()) {
    if (layout.CountImages(id, kind) > 0) cameras.push_back(id);
  }
  if (cameras.empty()) {
    throw InputError(options.dataset.string() + " has no camera with " + kind +
                     (options.masks ? "" : " (generated with --masks-only?)"));
  }
  std::filesystem::create_directories(options.log_dir);

  // SIGINT/SIGTERM are taken here and passed on to the nodes.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  const int64_t start_ns = RealtimeNowNs() + static_cast<int64_t>(options.start_delay_s * 1e9);
  std::map<pid_t, std::string> running;
  for (const std::string& id : cameras) {
    std::vector<std::string> args{
        options.node_binary.string(),
        "--camera-id",
        id,
        "--source",
        (options.masks ? "sim-masks:" : "sim:") + (options.dataset / id).string(),
        "--start-at",
        std::to_string(start_ns),
        "--speed",
        std::to_string(options.speed),
        "--linger",
        std::to_string(options.linger_s)};
    args.insert(args.end(), options.extra_args.begin(), options.extra_args.end());
    const std::filesystem::path log = options.log_dir / ("node-" + id + ".log");
    running[Spawn(args, log)] = id;
    spdlog::info("node {} started on {} ({}; log {})", id, (options.dataset / id).string(), kind,
                 log.string());
  }

  int failed = 0;
  const timespec tick{0, 100'000'000};
  while (!running.empty()) {
    if (sigtimedwait(&signals, nullptr, &tick) > 0) {
      spdlog::warn("stopping the nodes");
      for (const auto& [pid, id] : running)
        kill(pid, SIGTERM);
    }
    int status = 0;
    pid_t pid;
    while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
      auto it = running.find(pid);
      if (it == running.end()) continue;
      const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      if (!ok) {
        ++failed;
        spdlog::error("node {} ended badly ({}); see its log", it->second,
                      WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                        : "signal " + std::to_string(WTERMSIG(status)));
      } else {
        spdlog::info("node {} finished", it->second);
      }
      running.erase(it);
    }
  }
  return failed;
}

}  // namespace silnet::sim
