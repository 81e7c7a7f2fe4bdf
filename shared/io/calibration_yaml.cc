#include "shared/io/calibration_yaml.h"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core/eigen.hpp>
#include <optional>

#include "shared/geometry/nearest_rotation.h"
#include "shared/io/replace_yaml.h"
#include "shared/io/yaml_guard.h"
#include "shared/util/check.h"

namespace silnet {
namespace {

constexpr int kCalibrationVersion = 1;

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> ReadMatrix(const cv::FileNode& node, const char* name,
                                             const std::string& where) {
  const std::vector<double> values = ReadYamlMatrixEntries(node, name, where, {Rows * Cols});
  using Stored = Eigen::Matrix<double, Rows, Cols, Cols == 1 ? Eigen::ColMajor : Eigen::RowMajor>;
  return Eigen::Map<const Stored>(values.data());
}

int ReadPositiveInt(const cv::FileNode& node, const char* name, const std::string& where) {
  const cv::FileNode field = node[name];
  if (field.empty() || !field.isInt()) {
    throw InputError(where + ": missing integer '" + name + "'");
  }
  const int value = static_cast<int>(field);
  if (value <= 0) throw InputError(where + ": '" + name + "' must be positive");
  return value;
}

// An optional number field, `fallback` when absent; throws InputError if it is not a number.
double ReadReal(const cv::FileNode& node, const char* name, double fallback,
                const std::string& where) {
  const cv::FileNode field = node[name];
  if (field.empty()) return fallback;
  if (!field.isReal() && !field.isInt())
    throw InputError(where + ": '" + name + "' must be a number");
  return static_cast<double>(field);
}

template <class Derived>
cv::Mat ToMat(const Eigen::MatrixBase<Derived>& m) {
  cv::Mat out;
  cv::eigen2cv(Eigen::MatrixXd(m), out);
  return out;
}

}  // namespace

std::vector<double> ReadYamlMatrixEntries(const cv::FileNode& node, const char* name,
                                          const std::string& where,
                                          std::initializer_list<int64_t> allowed_sizes) {
  const cv::FileNode field = node[name];
  if (field.empty()) throw InputError(where + ": missing '" + name + "'");
  const auto check_size = [&](int64_t total) {
    if (std::find(allowed_sizes.begin(), allowed_sizes.end(), total) == allowed_sizes.end()) {
      throw InputError(where + ": '" + name + "' has " + std::to_string(total) +
                       " entries, expected " + std::to_string(*allowed_sizes.begin()));
    }
  };
  // The size a matrix declares, checked before OpenCV allocates it.
  if (field.isMap()) {
    const cv::FileNode rows = field["rows"], cols = field["cols"];
    if (!rows.isInt() || !cols.isInt())
      throw InputError(where + ": '" + name + "' is not a matrix (no integer rows and cols)");
    check_size(static_cast<int64_t>(static_cast<int>(rows)) * static_cast<int>(cols));
  }
  cv::Mat mat;
  try {
    field >> mat;
  } catch (const cv::Exception& e) {
    throw InputError(where + ": '" + name + "' is not a matrix (" + e.err + ")");
  }
  if (mat.channels() != 1)
    throw InputError(where + ": '" + name + "' is not a matrix (more than one channel)");
  check_size(static_cast<int64_t>(mat.total()));
  mat.convertTo(mat, CV_64F);
  std::vector<double> values(mat.begin<double>(), mat.end<double>());
  for (double v : values) {
    if (!std::isfinite(v)) throw InputError(where + ": '" + name + "' has non-finite entries");
  }
  return values;
}

void WriteCameras(cv::FileStorage& storage, const std::vector<CameraModel>& cameras) {
  storage << "cameras"
          << "[";
  for (const CameraModel& c : cameras) {
    storage << "{";
    storage << "id" << c.id << "image_width" << c.width << "image_height" << c.height;
    storage << "fps" << c.fps << "time_offset" << c.time_offset;
    storage << "K" << ToMat(c.K) << "dist" << ToMat(c.dist.transpose());
    storage << "R" << ToMat(c.R) << "t" << ToMat(c.t);
    storage << "}";
  }
  storage << "]";
}

std::vector<CameraModel> ReadCameras(const cv::FileNode& cameras, const std::string& source) {
  if (cameras.empty() || !cameras.isSeq()) {
    throw InputError(source + ": no 'cameras' sequence");
  }
  std::vector<CameraModel> out;
  int index = 0;
  for (const cv::FileNode& node : cameras) {
    std::string where = source + ": camera " + std::to_string(index++);
    if (!node.isMap()) throw InputError(where + ": not a map of fields (id, K, R, t, ...)");
    CameraModel c;
    if (node["id"].empty() || !node["id"].isString()) throw InputError(where + ": missing 'id'");
    c.id = static_cast<std::string>(node["id"]);
    if (c.id.empty()) throw InputError(where + ": 'id' is empty");
    where += " ('" + c.id + "')";
    c.width = ReadPositiveInt(node, "image_width", where);
    c.height = ReadPositiveInt(node, "image_height", where);
    c.K = ReadMatrix<3, 3>(node, "K", where);
    const std::vector<double> dist = ReadYamlMatrixEntries(node, "dist", where, {5, 4});
    for (size_t k = 0; k < dist.size(); ++k)
      c.dist[static_cast<Eigen::Index>(k)] = dist[k];
    c.R = ReadMatrix<3, 3>(node, "R", where);
    c.t = ReadMatrix<3, 1>(node, "t", where);
    c.fps = ReadReal(node, "fps", 30.0, where);
    c.time_offset = ReadReal(node, "time_offset", 0.0, where);
    if (!(c.K(0, 0) > 0) || !(c.K(1, 1) > 0) || c.K(2, 2) != 1.0 || c.K(1, 0) != 0.0 ||
        c.K(2, 0) != 0.0 || c.K(2, 1) != 0.0) {
      throw InputError(where +
                       ": K must be upper triangular with positive focal lengths and K(2,2) = 1");
    }
    // Rotations printed to four decimals or more are taken as the rotation nearest to them.
    const std::optional<Eigen::Matrix3d> rotation = NearestRotation(c.R, kPrintedRotationTolerance);
    if (!rotation) {
      throw InputError(
          fmt::format("{}: R is not a rotation matrix (not within {} of one in every element)",
                      where, kPrintedRotationTolerance));
    }
    c.R = *rotation;
    if (!(c.fps > 0) || !std::isfinite(c.fps)) throw InputError(where + ": fps must be positive");
    if (!std::isfinite(c.time_offset)) throw InputError(where + ": time_offset must be finite");
    for (const CameraModel& earlier : out) {
      if (earlier.id == c.id) throw InputError(where + ": a second camera with this id");
    }
    out.push_back(std::move(c));
  }
  return out;
}

cv::FileStorage OpenYamlForReading(const std::filesystem::path& path,
                                   std::chrono::milliseconds parse_limit) {
  return OpenFileStorageGuarded(path, "YAML", "not a silnet file: ", parse_limit);
}

void SaveCalibration(const std::filesystem::path& path, const std::vector<CameraModel>& cameras) {
  ReplaceYaml(path, [&](cv::FileStorage& storage) {
    storage << "silnet_calibration_version" << kCalibrationVersion;
    WriteCameras(storage, cameras);
  });
}

std::vector<CameraModel> LoadCalibration(const std::filesystem::path& path) {
  cv::FileStorage storage = OpenYamlForReading(path);
  return ReadYamlGuarded(path, "malformed",
                         [&] { return ReadCameras(storage["cameras"], path.string()); });
}

void WriteCameraMoves(cv::FileStorage& storage, const std::vector<CameraMoveRecord>& moves) {
  storage << "camera_moves"
          << "[";
  for (const CameraMoveRecord& m : moves) {
    storage << "{"
            << "frame" << m.frame;
    WriteCameras(storage, {m.camera});
    storage << "}";
  }
  storage << "]";
}

std::vector<CameraModel> LoadCamerasAtFrame(const std::filesystem::path& path, int frame) {
  cv::FileStorage storage = OpenYamlForReading(path);
  return ReadYamlGuarded(path, "malformed", [&] {
    std::vector<CameraModel> cameras = ReadCameras(storage["cameras"], path.string());
    const cv::FileNode moves = storage["camera_moves"];
    if (moves.empty()) return cameras;
    if (!moves.isSeq()) throw InputError(path.string() + ": camera_moves is not a sequence");
    std::vector<CameraMoveRecord> records;
    for (const cv::FileNode& m : moves) {
      if (m["frame"].empty()) throw InputError(path.string() + ": a camera move has no frame");
      const std::vector<CameraModel> moved = ReadCameras(m["cameras"], path.string());
      if (moved.size() != 1)
        throw InputError(path.string() + ": a camera move must hold exactly one camera");
      records.push_back({static_cast<int>(m["frame"]), moved.front()});
    }
    std::stable_sort(records.begin(), records.end(),
                     [](const auto& a, const auto& b) { return a.frame < b.frame; });
    for (const CameraMoveRecord& r : records) {
      auto it = std::find_if(cameras.begin(), cameras.end(),
                             [&](const CameraModel& c) { return c.id == r.camera.id; });
      if (it == cameras.end())
        throw InputError(path.string() + ": a camera move names unknown camera " + r.camera.id);
      if (r.frame <= frame) *it = r.camera;
    }
    return cameras;
  });
}

}  // namespace silnet
