#pragma once
// The real captures beside the project (../shared/data) in tests: a test that needs one skips
// when it is absent on a developer's machine, and fails where the data must be there (CI), so
// a missing folder never passes unnoticed as a skipped check.

#include <gtest/gtest.h>

#include <filesystem>

namespace silnet::testing {

// True where a missing real capture is a failure: the environment sets CI=true (as the CI
// run does) or SILNET_REQUIRE_REAL_DATA=1.
bool RealDataRequired();

}  // namespace silnet::testing

// Ends the current test unless `folder` exists: skipped, or failed when RealDataRequired().
#define SILNET_REQUIRE_REAL_DATA(folder)                                     \
  do {                                                                       \
    const std::filesystem::path silnet_real_data_folder = (folder);          \
    if (!std::filesystem::exists(silnet_real_data_folder)) {                 \
      if (::silnet::testing::RealDataRequired())                             \
        FAIL() << "no real data at " << silnet_real_data_folder              \
               << " (required here: CI=true or SILNET_REQUIRE_REAL_DATA=1)"; \
      GTEST_SKIP() << "no real data at " << silnet_real_data_folder;         \
    }                                                                        \
  } while (false)
