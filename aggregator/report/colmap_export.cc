#include "aggregator/report/colmap_export.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "aggregator/report/report_statistics.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// COLMAP puts the centre of the top-left pixel at (0.5, 0.5), silnet at (0, 0).
constexpr double kColmapPixelShift = 0.5;

// The COLMAP camera model line after the id: MODEL WIDTH HEIGHT PARAMS...
std::string CameraLine(const CameraModel& c) {
  const double fx = c.K(0, 0), fy = c.K(1, 1);
  const double cx = c.K(0, 2) + kColmapPixelShift, cy = c.K(1, 2) + kColmapPixelShift;
  std::string line = fmt::format("{} {} ", c.width, c.height);
  if (!c.HasDistortion()) return "PINHOLE " + line + fmt::format("{} {} {} {}", fx, fy, cx, cy);
  const Distortion& d = c.dist;
  if (d[4] == 0.0) {
    return "OPENCV " + line +
           fmt::format("{} {} {} {} {} {} {} {}", fx, fy, cx, cy, d[0], d[1], d[2], d[3]);
  }
  // k3 needs FULL_OPENCV, whose rational terms k4..k6 are zero here.
  return "FULL_OPENCV " + line +
         fmt::format("{} {} {} {} {} {} {} {} {} 0 0 0", fx, fy, cx, cy, d[0], d[1], d[2], d[3],
                     d[4]);
}

// One observation of an exported point in an exported image.
struct Observation {
  Eigen::Vector2d pixel;  // silnet convention
  size_t point_id = 0;
};

// The image name: the camera id with white space (which would split COLMAP's line) replaced
// by '_', and ".png".
std::string ImageName(const std::string& id) {
  std::string name = id;
  for (char& ch : name) {
    if (std::isspace(static_cast<unsigned char>(ch))) ch = '_';
  }
  return name + ".png";
}

std::ofstream OpenForWriting(const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("cannot write COLMAP file '{}'", path.string()));
  return out;
}

void Finish(std::ofstream* out, const std::filesystem::path& path) {
  out->flush();
  if (!*out) throw InputError(fmt::format("cannot write COLMAP file '{}'", path.string()));
}

}  // namespace

void WriteColmapText(const std::filesystem::path& dir, const NetworkCalibration& calibration) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    throw InputError(
        fmt::format("cannot create COLMAP folder '{}': {}", dir.string(), error.message()));
  }
  const size_t n = calibration.cameras.size();
  size_t placed = 0;
  for (size_t i = 0; i < n; ++i)
    placed += IsPlaced(calibration, i) ? 1 : 0;

  // Exported points: inliers with finite coordinates seen by two placed cameras.
  std::vector<std::vector<Observation>> observations(n);
  std::vector<size_t> exported;  // index into calibration.points, point id = position + 1
  for (size_t p = 0; p < calibration.points.size(); ++p) {
    const FrontierPoint& point = calibration.points[p];
    if (!point.inlier || !point.X.allFinite()) continue;
    if (!IsPlaced(calibration, point.views[0].camera) ||
        !IsPlaced(calibration, point.views[1].camera) ||
        point.views[0].camera == point.views[1].camera)
      continue;
    exported.push_back(p);
    for (const FrontierObservation& view : point.views)
      observations[view.camera].push_back({view.pixel, exported.size()});
  }

  // Camera and image ids are the camera's input index + 1 for every placed camera.
  const std::filesystem::path cameras_path = dir / "cameras.txt";
  std::ofstream cameras = OpenForWriting(cameras_path);
  cameras << "# Camera list with one line of data per camera:\n"
          << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
          << "# Number of cameras: " << placed << "\n";
  for (size_t i = 0; i < n; ++i) {
    if (IsPlaced(calibration, i))
      cameras << i + 1 << ' ' << CameraLine(calibration.cameras[i]) << '\n';
  }
  Finish(&cameras, cameras_path);

  const std::filesystem::path images_path = dir / "images.txt";
  std::ofstream images = OpenForWriting(images_path);
  const double mean_observations =
      placed == 0 ? 0.0 : 2.0 * static_cast<double>(exported.size()) / placed;
  images << "# Image list with two lines of data per image:\n"
         << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
         << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
         << fmt::format("# Number of images: {}, mean observations per image: {}\n", placed,
                        mean_observations);
  // POINT2D_IDX of each exported point's two observations, for the tracks.
  std::vector<std::array<size_t, 2>> point2d_index(exported.size());
  for (size_t i = 0; i < n; ++i) {
    if (!IsPlaced(calibration, i)) continue;
    const CameraModel& c = calibration.cameras[i];
    Eigen::Quaterniond q(c.R);  // cam_from_world, Hamilton, as COLMAP
    q.normalize();
    if (q.w() < 0.0) q.coeffs() *= -1.0;
    images << fmt::format("{} {} {} {} {} {} {} {} {} {}\n", i + 1, q.w(), q.x(), q.y(), q.z(),
                          c.t.x(), c.t.y(), c.t.z(), i + 1, ImageName(c.id));
    std::string line;
    for (size_t k = 0; k < observations[i].size(); ++k) {
      const Observation& o = observations[i][k];
      if (!line.empty()) line += ' ';
      line += fmt::format("{} {} {}", o.pixel.x() + kColmapPixelShift,
                          o.pixel.y() + kColmapPixelShift, o.point_id);
      const FrontierPoint& point = calibration.points[exported[o.point_id - 1]];
      point2d_index[o.point_id - 1][point.views[0].camera == i ? 0 : 1] = k;
    }
    images << line << '\n';
  }
  Finish(&images, images_path);

  const std::filesystem::path points_path = dir / "points3D.txt";
  std::ofstream points = OpenForWriting(points_path);
  points << "# 3D point list with one line of data per point:\n"
         << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
         << fmt::format("# Number of points: {}, mean track length: {}\n", exported.size(),
                        exported.empty() ? 0 : 2);
  for (size_t k = 0; k < exported.size(); ++k) {
    const FrontierPoint& p = calibration.points[exported[k]];
    const double mean_error = 0.5 * (p.views[0].error_px + p.views[1].error_px);
    points << fmt::format("{} {} {} {} 200 200 200 {} {} {} {} {}\n", k + 1, p.X.x(), p.X.y(),
                          p.X.z(), mean_error, p.views[0].camera + 1, point2d_index[k][0],
                          p.views[1].camera + 1, point2d_index[k][1]);
  }
  Finish(&points, points_path);
}

}  // namespace silnet::aggregator
