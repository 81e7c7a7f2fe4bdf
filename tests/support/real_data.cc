#include "tests/support/real_data.h"

#include <cstdlib>
#include <string_view>

namespace silnet::testing {

bool RealDataRequired() {
  const char* ci = std::getenv("CI");
  const char* required = std::getenv("SILNET_REQUIRE_REAL_DATA");
  return (ci != nullptr && std::string_view(ci) == "true") ||
         (required != nullptr && std::string_view(required) == "1");
}

}  // namespace silnet::testing
