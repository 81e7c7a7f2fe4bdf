#pragma once
// silnet-aggregator's subcommands: each adds its options to the CLI app and returns the
// function that runs it once parsed (exit code: 0 ok, 2 user error, 130 cancelled).

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace silnet::aggregator {
struct StereoJobResult;
}  // namespace silnet::aggregator

namespace silnet::aggregator::cli {

// A registered subcommand.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command AddIngestCommand(CLI::App& app);
Command AddPairsCommand(CLI::App& app);
Command AddCalibrateCommand(CLI::App& app);
Command AddHullsCommand(CLI::App& app);
Command AddStereoCommand(CLI::App& app);
Command AddStillsCommand(CLI::App& app);
Command AddLiveCommand(CLI::App& app);
Command AddStatusCommand(CLI::App& app);
Command AddRecalibrateCommand(CLI::App& app);

// Prints a stereo job's outcome (the model's figures, or why there is none) for the model
// written to `out`; returns the exit code (0, or 3 without a model).
int PrintStereoResult(const StereoJobResult& result, const std::string& out);

}  // namespace silnet::aggregator::cli
