#pragma once
// Simulated stereo stills with ground truth (`silnet-sim stills`): the stills statue
// (sim/scene/stills_statue.h) photographed once by a ring or dome of cameras aimed at it,
// written as the stereo job's stills folder (aggregator/stereo/stills_folder.h):
//   <dir>/<camera>/stills/000000.png   colour, BGR, textured and shaded, with sensor noise
//   <dir>/<camera>/masks/000000.png    exact silhouette, 0/255 (pixel centre rays)
//   <dir>/<camera>/background.png      with `write_backgrounds`: the empty room, other noise
//   <dir>/calibration.yaml             the cameras (shared/io/calibration_yaml.h)
//   <dir>/ground_truth.yaml            as `silnet-sim generate` writes it (one frame)
//   <dir>/gt_surface.ply               the statue's true outer surface: points with outward
//                                      normals (shared/io/point_cloud_ply.h), about one per
//                                      spacing^2, spacing half the mean pixel footprint at
//                                      the statue unless set; comments give both values
// The output depends only on the options (same seed, same bytes).

#include <filesystem>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "shared/util/progress.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"

namespace silnet::sim {

// The camera network defaults of stills: 16 cameras, no time offsets, aims within 5 cm of
// the statue's centre, no distortion.
CameraNetworkOptions StillsNetworkDefaults();

// Everything that defines a set of simulated stills.
struct StillsOptions {
  // Cameras; target_height is set to the statue's mid-height and radius from `fill` unless
  // `radius` is positive.
  CameraNetworkOptions network = StillsNetworkDefaults();
  // Given cameras (e.g. a live dataset's, carried over to a still resolution) used instead of
  // `network`, `radius` and `fill`: the statue stands at the origin, where they look.
  std::vector<CameraModel> cameras;
  double radius = 0.0;  // camera distance from the statue's centre, m; 0 = from `fill`
  double fill = 0.7;    // nominal share of the image height the statue's height fills
  RenderSettings render;
  double surface_spacing = 0.0;    // gt_surface.ply point spacing, m; 0 = half the footprint
  uint64_t seed = 1;               // cameras, texture, noise (overrides network/render seeds)
  bool write_backgrounds = false;  // also background.png per camera (for segmentation)
  int threads = 0;                 // 0 = all cores
  bool overwrite = false;          // allow writing into a non-empty folder

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// What GenerateStills produced.
struct StillsSummary {
  std::vector<CameraModel> cameras;
  double radius = 0.0;           // camera distance used, m
  double footprint = 0.0;        // mean pixel footprint at the statue's centre, m
  double surface_spacing = 0.0;  // gt_surface.ply spacing used, m
  std::size_t surface_points = 0;
  std::size_t images_written = 0;
  std::size_t bytes_written = 0;  // images and gt_surface.ply
  double seconds = 0.0;
};

// Paths of the stills layout above.
std::filesystem::path StillPath(const std::filesystem::path& dir, const std::string& camera,
                                int frame = 0);
std::filesystem::path StillMaskPath(const std::filesystem::path& dir, const std::string& camera,
                                    int frame = 0);
std::filesystem::path BackgroundPath(const std::filesystem::path& dir, const std::string& camera);

// Writes the stills folder into `output` (created if missing). Throws InputError for
// invalid options or a non-empty output folder without `overwrite`. Honours progress
// cancellation (throws std::runtime_error("cancelled")); `progress` may be null.
StillsSummary GenerateStills(const StillsOptions& options, const std::filesystem::path& output,
                             Progress* progress);

}  // namespace silnet::sim
