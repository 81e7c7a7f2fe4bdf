#include "shared/util/check.h"

namespace silnet::internal {

void ThrowCheckError(const char* file, int line, const char* condition,
                     const std::string& message) {
  std::ostringstream out;
  out << file << ":" << line << ": check failed: " << condition;
  if (!message.empty()) out << " (" << message << ")";
  throw CheckError(out.str());
}

}  // namespace silnet::internal
