#include "shared/dds/dds_error.h"

#include <filesystem>

namespace silnet::dds {

int32_t CheckDds(int32_t result, const std::string& what, std::source_location where) {
  if (result >= 0) return result;
  const std::string file = std::filesystem::path(where.file_name()).filename().string();
  throw DdsError(
      what + ": " + dds_strretcode(result) + " (" + file + ":" + std::to_string(where.line()) + ")",
      result);
}

}  // namespace silnet::dds
