// The one gtest main of silnet's tests: logging at warn (or SILNET_LOG_LEVEL), then all tests.

#include <gtest/gtest.h>

#include <cstdlib>

#include "shared/util/log.h"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const char* level = std::getenv("SILNET_LOG_LEVEL");
  silnet::ConfigureLogging("test", level != nullptr ? level : "warn");
  return RUN_ALL_TESTS();
}
