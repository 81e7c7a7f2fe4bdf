#pragma once
// Camera sets in OpenCV FileStorage YAML (DESIGN.md "Files"): a `cameras` sequence whose
// entries hold id, image_width, image_height, K, dist, R, t (x_cam = R X + t), fps and
// time_offset (frames). calibration.yaml and ground_truth.yaml share this block.

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <opencv2/core/persistence.hpp>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "shared/io/yaml_guard.h"

namespace silnet {

// Reads matrix field `name` of `node` as a flat vector of doubles; throws InputError naming
// `where` if it is missing, not a one-channel matrix, has non-finite entries or has a size
// not in `allowed_sizes` (a size the field declares is checked before OpenCV allocates it).
std::vector<double> ReadYamlMatrixEntries(const cv::FileNode& node, const char* name,
                                          const std::string& where,
                                          std::initializer_list<int64_t> allowed_sizes);

// Writes the `cameras` sequence into an open FileStorage.
void WriteCameras(cv::FileStorage& storage, const std::vector<CameraModel>& cameras);

// Reads a `cameras` sequence. Throws InputError naming `source` and the camera on a
// missing field, a matrix of the wrong size, an R not within 1e-4 of a rotation in every
// element (one within is replaced by that nearest rotation) or a non-positive focal length.
std::vector<CameraModel> ReadCameras(const cv::FileNode& cameras, const std::string& source);

// Writes calibration.yaml (format version 1) with the given cameras, replacing an older one at
// once (a reader never sees half of it). Throws InputError if it cannot be written.
void SaveCalibration(const std::filesystem::path& path, const std::vector<CameraModel>& cameras);

// Reads calibration.yaml (or any file with a `cameras` block, such as ground_truth.yaml).
// Throws InputError for a missing, unreadable or malformed file, a camera field that is not
// a number where one is due or not finite, and two cameras with one id.
std::vector<CameraModel> LoadCalibration(const std::filesystem::path& path);

// A camera that moved during a capture: from frame `frame` on it is `camera` (same id).
// Simulated ground truth lists these in a `camera_moves` sequence of {frame, cameras: [one
// camera block]} entries.
struct CameraMoveRecord {
  int frame = 0;
  CameraModel camera;
};

// Writes the `camera_moves` sequence into an open FileStorage.
void WriteCameraMoves(cv::FileStorage& storage, const std::vector<CameraMoveRecord>& moves);

// The cameras of a file with a `cameras` block as they were at `frame`: every `camera_moves`
// entry from that frame or earlier applied in order. Throws as LoadCalibration does, and
// for a move naming a camera the file does not hold.
std::vector<CameraModel> LoadCamerasAtFrame(const std::filesystem::path& path, int frame);

// Opens a FileStorage for reading; throws InputError with the path and the reason for a
// missing or unreadable file, one nested deeper than OpenCV's parser survives, one on which
// the parser crashes or is still running after `parse_limit` (yaml_guard.h), or one the
// parser refuses.
cv::FileStorage OpenYamlForReading(const std::filesystem::path& path,
                                   std::chrono::milliseconds parse_limit = kYamlParseLimit);

}  // namespace silnet
