// silnet-aggregator: the aggregator's jobs as subcommands.
//   ingest     subscribe to the nodes, store every session durably, request missing frames
//   pairs      every camera pair's epipolar geometry and time offset from the silhouettes
//   calibrate  pairs, synchronisation and calibration of the whole network
//   hulls      a visual hull per frame from silhouettes and a calibration
//   stereo     a surface model of a still subject from calibrated stills
//   live       the whole chain as the streams arrive (optionally as a service)
//   status     what the live job in a folder reports about its nodes and cameras
//   recalibrate  ask the live job in a folder to recalibrate

#include <CLI/CLI.hpp>
#include <cstdio>

#include "aggregator/cli/cli_support.h"
#include "aggregator/cli/commands.h"
#include "shared/dds/dds_error.h"
#include "shared/util/check.h"
#include "shared/util/log.h"

int main(int argc, char** argv) {
  namespace cli = silnet::aggregator::cli;
  CLI::App app{"silnet-aggregator: calibrate and synchronise camera networks from silhouettes"};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  const cli::Command commands[] = {
      cli::AddIngestCommand(app), cli::AddPairsCommand(app),  cli::AddCalibrateCommand(app),
      cli::AddHullsCommand(app),  cli::AddStereoCommand(app), cli::AddStillsCommand(app),
      cli::AddLiveCommand(app),   cli::AddStatusCommand(app), cli::AddRecalibrateCommand(app)};
  CLI11_PARSE(app, argc, argv);
  cli::WatchSignals();
  try {
    silnet::ConfigureLogging("silnet-aggregator", log_level);
    for (const cli::Command& command : commands) {
      if (command.app->parsed()) return command.run();
    }
  } catch (const silnet::InputError& e) {
    std::fprintf(stderr, "silnet-aggregator: %s\n", e.what());
    return 2;
  } catch (const silnet::dds::DdsError& e) {
    std::fprintf(stderr, "silnet-aggregator: DDS failed: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "silnet-aggregator: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
