#pragma once
// ground_truth.yaml of a simulated dataset (OpenCV FileStorage):
//   silnet_ground_truth_version  1
//   scene: subject kind, subject count, layout, seed, reference_fps, frames
//   cameras: the shared camera block (shared/io/calibration_yaml.h), with fps and time_offset,
//          as at frame 0
//   camera_moves: cameras that moved during the capture (shared/io/calibration_yaml.h)
//   pairs: for every i < j: i, j, F (x_j^T F x_i = 0, undistorted pixels, unit norm),
//          offset and rate (frame k of i is simultaneous with offset + rate * k of j)
//   part_names: "<subject>/<part>" for every (subject, part) pair
//   subject_frames: first (reference frame index), count, and per reference frame r
//          (time r / reference_fps) a matrix with one row per primitive:
//          kind (0 capsule, 1 ellipsoid), subject, part, a(3), b(3), radius,
//          center(3), radii(3), axes(9, row-major)

#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "shared/io/calibration_yaml.h"
#include "sim/scene/scene.h"

namespace silnet::sim {

// Scene summary stored with the ground truth.
struct GroundTruthScene {
  std::string subject;
  int subjects = 1;
  std::string layout;
  uint64_t seed = 0;
  double reference_fps = 30.0;
  int frames = 0;
};

// Writes ground_truth.yaml for cameras that saw `scene`; subject geometry is stored for
// every reference frame that covers the cameras' exposure times.
// Pairs describe the cameras as at frame 0; `moves` (if any) are written as camera_moves.
void WriteGroundTruth(const std::filesystem::path& path, const GroundTruthScene& summary,
                      const std::vector<CameraModel>& cameras, const Scene& scene,
                      const std::vector<CameraMoveRecord>& moves = {});

// The reference frame range [first, first + count) covering all exposures of `frames`
// frames of every camera, at `reference_fps`.
std::pair<int, int> ReferenceFrameRange(const std::vector<CameraModel>& cameras, int frames,
                                        double reference_fps);

// Primitives from one subject_frames row matrix (the inverse of the writer's encoding).
std::vector<Primitive> DecodePrimitiveRows(const cv::Mat& rows);

}  // namespace silnet::sim
