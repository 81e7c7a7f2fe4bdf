#include "shared/util/progress.h"

#include <fmt/format.h>

#include <cstdio>

namespace silnet {

Progress::Progress(std::string task, std::size_t total, Callback callback,
                   std::chrono::milliseconds min_interval)
    : task_(std::move(task)),
      total_(total),
      callback_(std::move(callback)),
      min_interval_(min_interval),
      start_(std::chrono::steady_clock::now()),
      last_report_(start_) {}

void Progress::Restart(std::string task, std::size_t total) {
  std::lock_guard lock(report_mutex_);
  task_ = std::move(task);
  total_ = total;
  done_ = 0;
  start_ = std::chrono::steady_clock::now();
  last_report_ = start_;
}

ProgressUpdate Progress::Snapshot(bool finished) const {
  ProgressUpdate update;
  update.task = task_;
  update.done = done_.load();
  update.total = total_.load();
  update.finished = finished;
  update.elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (update.done > 0 && update.total >= update.done) {
    update.remaining_s = update.elapsed_s * static_cast<double>(update.total - update.done) /
                         static_cast<double>(update.done);
  }
  return update;
}

void Progress::Advance(std::size_t n) {
  done_.fetch_add(n);
  if (!callback_) return;
  const auto now = std::chrono::steady_clock::now();
  std::unique_lock lock(report_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || now - last_report_ < min_interval_) return;
  last_report_ = now;
  callback_(Snapshot(false));
}

void Progress::Finish() {
  if (!callback_) return;
  std::lock_guard lock(report_mutex_);
  callback_(Snapshot(true));
}

Progress::Callback ConsoleProgressPrinter() {
  return [](const ProgressUpdate& u) {
    const double percent =
        u.total > 0 ? 100.0 * static_cast<double>(u.done) / static_cast<double>(u.total) : 100.0;
    std::string line =
        fmt::format("[{}] {}/{} ({:.0f}%) {:.1f} s", u.task, u.done, u.total, percent, u.elapsed_s);
    if (u.finished) {
      line += ", done";
    } else if (u.remaining_s >= 0) {
      line += fmt::format(", ~{:.0f} s left", u.remaining_s);
    }
    std::fprintf(stderr, "%s\n", line.c_str());
  };
}

}  // namespace silnet
