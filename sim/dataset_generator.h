#pragma once
// Generates a simulated dataset folder (shared/io/dataset_layout.h): per camera the exact
// silhouette masks and/or the colour frames, plus ground_truth.yaml. Rendering runs on
// several threads; the output depends only on the options (same seed, same bytes).

#include <filesystem>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "shared/util/progress.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"
#include "sim/scene/scene.h"

namespace silnet::sim {

// Everything that defines a simulated dataset.
struct SimulationOptions {
  CameraNetworkOptions network;
  SceneOptions scene;  // time_begin/time_end are set to cover the exposures
  RenderSettings render;
  int frames = 600;               // frames per camera
  std::vector<CameraMove> moves;  // cameras knocked out of place (at most one move each)
  bool write_masks = true;
  bool write_frames = true;
  int threads = 0;         // 0 = all cores
  bool overwrite = false;  // allow writing into a non-empty folder

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// What GenerateDataset produced.
struct SimulationSummary {
  std::vector<CameraModel> cameras;  // as at frame 0
  int frames = 0;
  std::size_t images_written = 0;
  std::size_t bytes_written = 0;
  double seconds = 0.0;
};

// The scene options of `options` with the motion's time range covering every exposure of
// every camera (plus a margin).
SceneOptions SceneForCameras(const SimulationOptions& options,
                             const std::vector<CameraModel>& cameras);

// Throws InputError if `output` exists and is not empty, unless `overwrite`.
void RequireWritableOutput(const std::filesystem::path& output, bool overwrite);

// Writes the dataset into `output` (created if missing). Throws InputError for invalid
// options or a non-empty output folder without `overwrite`. Honours progress cancellation
// (throws std::runtime_error("cancelled")).
SimulationSummary GenerateDataset(const SimulationOptions& options,
                                  const std::filesystem::path& output, Progress* progress);

}  // namespace silnet::sim
