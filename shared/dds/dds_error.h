#pragma once
// Errors from the Cyclone DDS C API turned into exceptions that say what failed and where.

#include <dds/dds.h>

#include <stdexcept>
#include <string>

namespace silnet::dds {

// A DDS call failed. what() reads "<what>: <Cyclone's reason> (file:line)".
class DdsError : public std::runtime_error {
 public:
  DdsError(const std::string& message, dds_return_t code)
      : std::runtime_error(message), code_(code) {}
  dds_return_t code() const { return code_; }

 private:
  dds_return_t code_;
};

// Returns `result` unchanged if it is not an error code (>= 0); otherwise throws DdsError.
// `what` names the operation, e.g. "create reader for silnet/hull_frame".
// The caller's file and line come from compiler builtins (std::source_location is not
// usable with clang 14 and libstdc++ 12, the fuzzing toolchain).
int32_t CheckDds(int32_t result, const std::string& what, const char* file = __builtin_FILE(),
                 int line = __builtin_LINE());

}  // namespace silnet::dds
