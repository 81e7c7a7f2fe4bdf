// The one gtest main of silnet's tests: logging at warn (or SILNET_LOG_LEVEL), a DDS domain of
// the binary's own when run outside ctest, then all tests.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "shared/util/log.h"

namespace {

// ctest gives every test binary a DDS domain of its own on loopback (tests/CMakeLists.txt).
// A binary run by hand gets one from its process id instead of domain 0, so two run side by
// side do not talk to each other's nodes; the processes it starts inherit it.
void DefaultTestDdsEnvironment() {
  if (std::getenv("SILNET_DDS_DOMAIN") == nullptr) {
    const std::string id = std::to_string(1 + getpid() % 230);
    setenv("SILNET_DDS_DOMAIN", id.c_str(), 0);
  }
  setenv("SILNET_DDS_LOOPBACK", "1", 0);
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  DefaultTestDdsEnvironment();
  const char* level = std::getenv("SILNET_LOG_LEVEL");
  silnet::ConfigureLogging("test", level != nullptr ? level : "warn");
  return RUN_ALL_TESTS();
}
