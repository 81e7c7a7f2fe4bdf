#include "shared/util/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

#include "shared/util/check.h"

namespace silnet {

void ConfigureLogging(const std::string& program, const std::string& level) {
  const spdlog::level::level_enum parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off") {
    throw InputError("unknown log level '" + level +
                     "' (use trace, debug, info, warn, error or off)");
  }
  auto logger = spdlog::stderr_color_mt(program);
  logger->set_pattern("%H:%M:%S.%e %^%L%$ [%n] %v");
  logger->set_level(parsed);
  spdlog::set_default_logger(logger);
}

}  // namespace silnet
