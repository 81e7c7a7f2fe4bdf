#pragma once
// Progress and cancellation for long jobs (dataset generation, pairs, calibration, hulls).
// A job advances a Progress from any thread; the Progress forwards rate-limited updates
// to a callback (the CLI prints them, tests ignore them) and carries a cancellation flag
// the job polls between work items.

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>

namespace silnet {

// A snapshot of a job's progress.
struct ProgressUpdate {
  std::string task;
  std::size_t done = 0;
  std::size_t total = 0;
  double elapsed_s = 0.0;
  // Estimated seconds left; negative while unknown.
  double remaining_s = -1.0;
  bool finished = false;
};

// Thread-safe progress counter with rate-limited reporting and cancellation.
class Progress {
 public:
  using Callback = std::function<void(const ProgressUpdate&)>;

  // `min_interval` bounds how often `callback` runs (the final update always runs).
  explicit Progress(std::string task, std::size_t total, Callback callback = {},
                    std::chrono::milliseconds min_interval = std::chrono::milliseconds(500));

  // Starts a new stage of the job: another task name and total, the count back to zero
  // (the callback and the cancellation flag stay). Call between stages, not concurrently.
  void Restart(std::string task, std::size_t total);
  // Adds `n` finished items; calls the callback if the interval has passed.
  void Advance(std::size_t n = 1);
  // Reports the job finished (always calls the callback once).
  void Finish();
  // Asks the job to stop at its next check; safe from any thread or signal-free context.
  void Cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }
  std::size_t done() const { return done_.load(); }
  std::size_t total() const { return total_.load(); }

 private:
  ProgressUpdate Snapshot(bool finished) const;

  std::string task_;
  std::atomic<std::size_t> total_;
  Callback callback_;
  std::chrono::milliseconds min_interval_;
  std::chrono::steady_clock::time_point start_;
  std::atomic<std::size_t> done_{0};
  std::atomic<bool> cancelled_{false};
  std::mutex report_mutex_;
  std::chrono::steady_clock::time_point last_report_;
};

// A callback that prints one line per update to stderr: "[task] 120/600 (20%) 3.1 s, ~12 s left".
Progress::Callback ConsoleProgressPrinter();

}  // namespace silnet
