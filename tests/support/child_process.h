#pragma once
// A child process for multi-process tests: started with posix_spawn, its standard output
// and error captured to files, waited for with a timeout, killed on destruction.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace silnet::testing {

// One running program.
class ChildProcess {
 public:
  // Starts `program` with `args`; the environment is the parent's plus `extra_env`.
  // Output goes to files in `log_dir` named after the program and pid. Throws on failure.
  ChildProcess(const std::filesystem::path& program, const std::vector<std::string>& args,
               const std::filesystem::path& log_dir,
               const std::map<std::string, std::string>& extra_env = {});
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Waits for the process to end; returns its exit status (128 + signal if killed) or
  // nullopt if it is still running after `timeout`.
  std::optional<int> Wait(std::chrono::milliseconds timeout);
  // Sends `signal` (default SIGKILL) and reaps the process.
  void Kill(int signal = 9);
  // Sends a signal without waiting.
  void Signal(int signal);
  bool running() const { return !exit_status_.has_value(); }
  pid_t pid() const { return pid_; }
  // What the process wrote so far.
  std::string Stdout() const;
  std::string Stderr() const;

 private:
  pid_t pid_ = -1;
  std::optional<int> exit_status_;
  std::filesystem::path stdout_path_, stderr_path_;
};

}  // namespace silnet::testing
