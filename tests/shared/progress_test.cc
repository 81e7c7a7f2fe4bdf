#include "shared/util/progress.h"

#include <gtest/gtest.h>

#include <vector>

namespace silnet {
namespace {

TEST(Progress, ReportsRateLimitedUpdatesAndAFinalOne) {
  std::vector<ProgressUpdate> updates;
  Progress progress(
      "job", 10, [&](const ProgressUpdate& u) { updates.push_back(u); },
      std::chrono::milliseconds(0));
  for (int i = 0; i < 10; ++i)
    progress.Advance();
  progress.Finish();
  ASSERT_FALSE(updates.empty());
  EXPECT_TRUE(updates.back().finished);
  EXPECT_EQ(updates.back().done, 10u);
  EXPECT_EQ(updates.back().task, "job");
}

TEST(Progress, CancellationIsVisible) {
  Progress progress("job", 1);
  EXPECT_FALSE(progress.cancelled());
  progress.Cancel();
  EXPECT_TRUE(progress.cancelled());
}

}  // namespace
}  // namespace silnet
