#pragma once
// Programmer-error checks. A failed SILNET_CHECK throws silnet::CheckError naming the
// file, line and condition; it is for broken invariants, not for bad user input (user
// errors are reported through return values or InputError with a readable reason).

#include <sstream>
#include <stdexcept>
#include <string>

namespace silnet {

// Thrown when an internal invariant does not hold.
class CheckError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// Thrown for bad user input (files, options, samples) with a message meant for a user.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace internal {
[[noreturn]] void ThrowCheckError(const char* file, int line, const char* condition,
                                  const std::string& message);
}  // namespace internal

}  // namespace silnet

#define SILNET_CHECK(condition)                                                                \
  do {                                                                                         \
    if (!(condition)) ::silnet::internal::ThrowCheckError(__FILE__, __LINE__, #condition, ""); \
  } while (false)

#define SILNET_CHECK_MSG(condition, message)                              \
  do {                                                                    \
    if (!(condition)) {                                                   \
      std::ostringstream silnet_check_stream_;                            \
      silnet_check_stream_ << message;                                    \
      ::silnet::internal::ThrowCheckError(__FILE__, __LINE__, #condition, \
                                          silnet_check_stream_.str());    \
    }                                                                     \
  } while (false)
