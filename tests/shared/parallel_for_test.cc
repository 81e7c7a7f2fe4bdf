#include "shared/util/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace silnet {
namespace {

TEST(ParallelFor, RunsEveryIndexExactlyOnce) {
  std::vector<std::atomic<int>> hits(1000);
  ParallelFor(hits.size(), 4, [&](size_t i) { hits[i]++; });
  for (const auto& h : hits)
    EXPECT_EQ(h.load(), 1);
}

TEST(ParallelFor, RethrowsTheFirstErrorAndStops) {
  // Every item throws, so each thread stops after its first item whatever the scheduling.
  std::atomic<int> calls{0};
  EXPECT_THROW(ParallelFor(100000, 2,
                           [&](size_t) {
                             calls++;
                             throw std::runtime_error("boom");
                           }),
               std::runtime_error);
  EXPECT_GE(calls.load(), 1);
  EXPECT_LE(calls.load(), 2);
}

// Once cancelled, no further item is handed out: on one thread, none after the one that
// cancelled.
TEST(ParallelFor, StopsHandingOutItemsOnceCancelled) {
  Progress progress("work", 1000);
  std::vector<int> hits(1000, 0);
  ParallelFor(hits.size(), 1, &progress, [&](size_t i) {
    hits[i] = 1;
    if (i == 10) progress.Cancel();
  });
  for (size_t i = 0; i < hits.size(); ++i)
    EXPECT_EQ(hits[i], i <= 10 ? 1 : 0) << i;
  Progress idle("work", 100);
  std::atomic<int> calls{0};
  ParallelFor(100, 2, &idle, [&](size_t) { calls++; });
  EXPECT_EQ(calls.load(), 100);
}

TEST(ParallelFor, ResolvesThreadCounts) {
  EXPECT_EQ(ResolveThreadCount(8, 3), 3);
  EXPECT_GE(ResolveThreadCount(0, 100), 1);
  EXPECT_EQ(ResolveThreadCount(2, 0), 1);
}

}  // namespace
}  // namespace silnet
