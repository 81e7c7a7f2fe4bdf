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

TEST(ParallelFor, ResolvesThreadCounts) {
  EXPECT_EQ(ResolveThreadCount(8, 3), 3);
  EXPECT_GE(ResolveThreadCount(0, 100), 1);
  EXPECT_EQ(ResolveThreadCount(2, 0), 1);
}

}  // namespace
}  // namespace silnet
