#include "shared/util/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace silnet {

int ResolveThreadCount(int threads, std::size_t n) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return static_cast<int>(
      std::min<std::size_t>(static_cast<std::size_t>(threads), std::max<std::size_t>(n, 1)));
}

void ParallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& fn) {
  ParallelFor(n, threads, nullptr, fn);
}

void ParallelFor(std::size_t n, int threads, const Progress* cancel,
                 const std::function<void(std::size_t)>& fn) {
  const int count = ResolveThreadCount(threads, n);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    while (!failed.load() && !(cancel && cancel->cancelled())) {
      const std::size_t i = next.fetch_add(1);
      if (i >= n) return;
      try {
        fn(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed.store(true);
      }
    }
  };
  std::vector<std::jthread> pool;
  for (int t = 1; t < count; ++t)
    pool.emplace_back(worker);
  worker();
  pool.clear();
  if (error) std::rethrow_exception(error);
}

}  // namespace silnet
