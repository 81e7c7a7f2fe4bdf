#pragma once
// Starts a real silnet-node process per camera of a simulated dataset, replaying that
// camera's feed (colour frames, which each node segments itself, or masks) live over DDS,
// all starting at the same instant; waits for them and passes SIGINT/SIGTERM on. The nodes
// join the DDS domain of the environment (SILNET_DDS_*), as every silnet program does.

#include <filesystem>
#include <string>
#include <vector>

namespace silnet::sim {

// Settings of a launch.
struct NodeLaunchOptions {
  std::filesystem::path dataset;        // written by `silnet-sim generate`
  std::filesystem::path node_binary;    // silnet-node
  std::filesystem::path log_dir;        // node-<camera>.log files; created
  double speed = 1.0;                   // replay speed (1 = the cameras' frame rates)
  bool masks = false;                   // replay the masks instead of the colour frames
  double start_delay_s = 2.0;           // the common start is this far in the future
  double linger_s = 10.0;               // nodes stay this long after their feed ends
  std::vector<std::string> extra_args;  // passed to every node
};

// Runs the nodes to the end. Returns how many ended with a non-zero status (or were killed).
// Throws InputError if the dataset has no camera with the feed asked for or the node binary
// is missing, and CheckError if a process cannot be started.
int RunNodes(const NodeLaunchOptions& options);

}  // namespace silnet::sim
