#pragma once
// Logging for every silnet program: spdlog's default logger writing to stderr with a
// timestamp, level and program name. Library code logs through spdlog::info() etc.

#include <spdlog/spdlog.h>

#include <string>

namespace silnet {

// Sets the default logger's pattern and level. `level` is one of trace, debug, info,
// warn, error, off; an unknown name throws InputError naming the accepted values.
void ConfigureLogging(const std::string& program, const std::string& level = "info");

}  // namespace silnet
