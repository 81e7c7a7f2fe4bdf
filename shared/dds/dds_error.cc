#include "shared/dds/dds_error.h"

#include <filesystem>

namespace silnet::dds {

int32_t CheckDds(int32_t result, const std::string& what, const char* file, int line) {
  if (result >= 0) return result;
  const std::string name = std::filesystem::path(file).filename().string();
  throw DdsError(
      what + ": " + dds_strretcode(result) + " (" + name + ":" + std::to_string(line) + ")",
      result);
}

}  // namespace silnet::dds
