// silnet-aggregator status OUT / recalibrate OUT: look at and command the live job running
// in OUT (aggregator/live/service_control.h).

#include <cstdio>

#include "aggregator/cli/commands.h"
#include "aggregator/live/service_control.h"

namespace silnet::aggregator::cli {

Command AddStatusCommand(CLI::App& app) {
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "status", "the nodes and camera motion of the live job in a folder (running or not)");
  cmd->add_option("out", *out, "the live job's output folder")->required();
  return {cmd, [out] {
            std::printf("%s", LiveStatusText(*out).c_str());
            return 0;
          }};
}

Command AddRecalibrateCommand(CLI::App& app) {
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "recalibrate", "ask the live job running in a folder to recalibrate on the newest frames");
  cmd->add_option("out", *out, "the live job's output folder")->required();
  return {cmd, [out] {
            const int pid = RequestRecalibration(*out);
            std::printf(
                "asked the live job (process %d) to recalibrate; its log and %s/%s say "
                "when the new calibration is published\n",
                pid, out->c_str(), "live_summary.yaml at exit");
            return 0;
          }};
}

}  // namespace silnet::aggregator::cli
