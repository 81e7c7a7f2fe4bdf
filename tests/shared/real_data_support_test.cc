// The real-data guard of the tests themselves: where the data must be there, a missing
// capture fails the test instead of skipping it.

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "tests/support/real_data.h"

namespace silnet::testing {
namespace {

// Sets an environment variable for the object's life, then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value != nullptr)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void RequireMissingCapture() {
  SILNET_REQUIRE_REAL_DATA("/nonexistent/silnet-real-capture");
}

TEST(RealDataSupport, RequiredUnderCiOrWhenAsked) {
  {
    const ScopedEnv ci("CI", nullptr), asked("SILNET_REQUIRE_REAL_DATA", nullptr);
    EXPECT_FALSE(RealDataRequired());
  }
  {
    const ScopedEnv ci("CI", "true"), asked("SILNET_REQUIRE_REAL_DATA", nullptr);
    EXPECT_TRUE(RealDataRequired());
  }
  {
    const ScopedEnv ci("CI", "false"), asked("SILNET_REQUIRE_REAL_DATA", "1");
    EXPECT_TRUE(RealDataRequired());
  }
}

TEST(RealDataSupport, MissingCaptureFailsWhereRequired) {
  const ScopedEnv asked("SILNET_REQUIRE_REAL_DATA", "1");
  EXPECT_FATAL_FAILURE(RequireMissingCapture(),
                       "no real data at \"/nonexistent/silnet-real-capture\"");
}

}  // namespace
}  // namespace silnet::testing
