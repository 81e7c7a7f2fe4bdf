#include "aggregator/hulls/real_datasets.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>

#include "aggregator/calibration/projective_geometry.h"
#include "shared/geometry/nearest_rotation.h"
#include "shared/io/yaml_guard.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

std::ifstream OpenOrThrow(const std::filesystem::path& path, std::ios::openmode mode) {
  std::ifstream in(path, mode);
  if (!in) throw InputError(fmt::format("cannot open {}", path.string()));
  return in;
}

// Next whitespace-separated PBM header token, skipping '#' comments to the end of the line.
std::string PbmToken(std::istream& in) {
  std::string token;
  while (in) {
    const int ch = in.get();
    if (ch == '#') {
      std::string comment;
      std::getline(in, comment);
      if (!token.empty()) return token;
    } else if (std::isspace(ch) || ch == EOF) {
      if (!token.empty()) return token;
    } else {
      token.push_back(static_cast<char>(ch));
    }
  }
  return token;
}

CameraModel SingleInstantCamera(std::string id, const cv::Mat& mask) {
  CameraModel camera;
  camera.id = std::move(id);
  camera.width = mask.cols;
  camera.height = mask.rows;
  return camera;
}

// The first of `names` that `fs` holds, as a CV_64F matrix with `values` elements.
cv::Mat ReadMatrix(const cv::FileStorage& fs, std::initializer_list<const char*> names, int values,
                   const std::filesystem::path& path) {
  for (const char* name : names) {
    cv::Mat m;
    fs[name] >> m;
    if (m.empty()) continue;
    if (static_cast<int>(m.total()) != values) {
      throw InputError(
          fmt::format("{}: {} has {} values, expected {}", path.string(), name, m.total(), values));
    }
    m.convertTo(m, CV_64F);
    if (!cv::checkRange(m))
      throw InputError(fmt::format("{}: {} holds a value that is not finite", path.string(), name));
    return m.reshape(1, 1);
  }
  throw InputError(fmt::format("{}: no {}", path.string(), *names.begin()));
}

// The frame size of the first .avi file in `folder`.
cv::Size VideoFrameSize(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> videos;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".avi") videos.push_back(entry.path());
  }
  std::sort(videos.begin(), videos.end());
  if (videos.empty()) throw InputError(fmt::format("{}: no .avi video", folder.string()));
  cv::VideoCapture capture(videos.front().string());
  cv::Mat frame;
  if (!capture.isOpened() || !capture.read(frame) || frame.empty())
    throw InputError(fmt::format("{}: cannot decode", videos.front().string()));
  return frame.size();
}

}  // namespace

std::vector<CameraModel> LoadUtrechtCameras(const std::filesystem::path& folder, double fps) {
  std::vector<std::filesystem::path> dirs;
  if (!std::filesystem::is_directory(folder))
    throw InputError(fmt::format("{}: not a folder", folder.string()));
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.is_directory() && std::filesystem::exists(entry.path() / "config.xml"))
      dirs.push_back(entry.path());
  }
  std::sort(dirs.begin(), dirs.end());
  if (dirs.empty())
    throw InputError(fmt::format("{}: no camera folder with config.xml", folder.string()));
  std::vector<CameraModel> cameras;
  for (const std::filesystem::path& dir : dirs) {
    const std::filesystem::path path = dir / "config.xml";
    // OpenCV's XML parser crashes on some malformed files: tried in a child process first.
    const cv::FileStorage fs = OpenFileStorageGuarded(path, "XML");
    // OpenCV throws its own exception for a matrix node it cannot read (a bad type letter,
    // text among the numbers): a malformed file like any other.
    cv::Mat k, dist, rvec, tvec;
    ReadYamlGuarded(path, "malformed", [&] {
      k = ReadMatrix(fs, {"camera_matrix", "CameraMatrix"}, 9, path);
      dist = ReadMatrix(fs, {"distortion_coefficients", "DistortionCoeffs"}, 5, path);
      rvec = ReadMatrix(fs, {"rotation_vectors", "Rotation"}, 3, path);
      tvec = ReadMatrix(fs, {"translation_vectors", "Translation"}, 3, path);
    });
    CameraModel camera;
    camera.id = dir.filename().string();
    const cv::Size size = VideoFrameSize(dir);
    camera.width = size.width;
    camera.height = size.height;
    camera.fps = fps;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        camera.K(r, c) = k.at<double>(0, 3 * r + c);
    }
    if (!(camera.K(0, 0) > 0.0 && camera.K(1, 1) > 0.0))
      throw InputError(fmt::format("{}: the camera matrix has no focal length", path.string()));
    if (camera.K(1, 0) != 0.0 || camera.K.row(2) != Eigen::RowVector3d(0.0, 0.0, 1.0)) {
      throw InputError(fmt::format(
          "{}: the camera matrix is not upper triangular with a last row of 0 0 1", path.string()));
    }
    for (int i = 0; i < 5; ++i)
      camera.dist[i] = dist.at<double>(0, i);
    cv::Mat rotation;
    cv::Rodrigues(rvec.reshape(1, 3), rotation);
    cv::cv2eigen(rotation, camera.R);
    for (int i = 0; i < 3; ++i)
      camera.t[i] = tvec.at<double>(0, i);
    cameras.push_back(camera);
  }
  return cameras;
}

cv::Mat ReadPbm(const std::filesystem::path& path, int foreground_bit) {
  std::ifstream in = OpenOrThrow(path, std::ios::binary);
  if (PbmToken(in) != "P4")
    throw InputError(fmt::format("{} is not a binary PBM (P4)", path.string()));
  int width = 0, height = 0;
  try {
    width = std::stoi(PbmToken(in));
    height = std::stoi(PbmToken(in));
  } catch (const std::exception&) {
    throw InputError(fmt::format("{}: malformed PBM size", path.string()));
  }
  // A camera image, not a size whose buffer cannot be allocated or whose row length overflows.
  constexpr int kMaxSide = 1 << 16;
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide) {
    throw InputError(fmt::format("{}: bad PBM size {}x{} (1 to {} pixels a side)", path.string(),
                                 width, height, kMaxSide));
  }
  // PbmToken consumed the single whitespace byte after the height; raster rows follow, and
  // must all be there before the mask is allocated.
  const size_t row_bytes = (static_cast<size_t>(width) + 7) / 8;
  const std::streampos raster = in.tellg();
  in.seekg(0, std::ios::end);
  const auto available = static_cast<size_t>(in.tellg() - raster);
  in.seekg(raster);
  if (available < row_bytes * static_cast<size_t>(height)) {
    throw InputError(
        fmt::format("{} is truncated at row {}", path.string(), available / row_bytes));
  }
  std::vector<unsigned char> row(row_bytes);
  cv::Mat mask(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    if (!in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(row_bytes)))
      throw InputError(fmt::format("{} is truncated at row {}", path.string(), y));
    for (int x = 0; x < width; ++x) {
      const int bit = (row[static_cast<size_t>(x / 8)] >> (7 - x % 8)) & 1;
      mask.at<uint8_t>(y, x) = bit == foreground_bit ? 255 : 0;
    }
  }
  return mask;
}

RealCapture LoadInriaDancer(const std::filesystem::path& folder) {
  const std::filesystem::path par = folder / "dancer_par.txt";
  std::ifstream in = OpenOrThrow(par, std::ios::in);
  int count = 0;
  if (!(in >> count) || count <= 0)
    throw InputError(fmt::format("{}: bad view count", par.string()));
  RealCapture capture;
  for (int v = 0; v < count; ++v) {
    std::string name;
    Matrix34d p;
    in >> name;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c)
        in >> p(r, c);
    }
    if (!in) throw InputError(fmt::format("{}: view {} is malformed", par.string(), v + 1));
    const cv::Mat mask = ReadPbm(folder / name, 0);
    CameraModel camera = SingleInstantCamera(std::filesystem::path(name).stem().string(), mask);
    if (!DecomposeProjection(p, &camera.K, &camera.R, &camera.t))
      throw InputError(fmt::format("{}: the projection of {} is singular", par.string(), name));
    capture.cameras.push_back(camera);
    capture.masks.push_back(mask);
  }
  return capture;
}

RealCapture LoadEpvhAlien(const std::filesystem::path& folder, int views) {
  constexpr int kViews = 24, kWidth = 1900, kHeight = 1600, kShift = 4;
  if (views < 0 || views > kViews)
    throw InputError(fmt::format("the alien set has {} views, not {}", kViews, views));
  if (views == 0) views = kViews;
  const std::filesystem::path camera_path = folder / "alien-camera.txt";
  const std::filesystem::path contour_path = folder / "alien-contour.txt";
  std::ifstream cameras = OpenOrThrow(camera_path, std::ios::in);
  std::ifstream contours = OpenOrThrow(contour_path, std::ios::in);
  RealCapture capture;
  for (int v = 0; v < views; ++v) {
    Matrix34d p;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c)
        cameras >> p(r, c);
    }
    if (!cameras)
      throw InputError(fmt::format("{}: camera {} is malformed", camera_path.string(), v));
    int index = -1, count = 0;
    contours >> index >> count;
    // At most eight points per pixel of the image's perimeter (the set's longest contour has
    // 11 608), not a count whose buffer cannot be allocated.
    constexpr int kMaxPoints = 16 * (kWidth + kHeight);
    if (!contours || index != v || count < 3 || count > kMaxPoints)
      throw InputError(fmt::format("{}: contour {} is malformed", contour_path.string(), v));
    std::vector<cv::Point> polygon(static_cast<size_t>(count));
    for (cv::Point& point : polygon) {
      double x = 0, y = 0;
      contours >> x >> y;
      // Within a few images of the frame, so the fixed-point coordinates below fit an int.
      if (!(std::abs(x) < 1e6 && std::abs(y) < 1e6)) contours.setstate(std::ios::failbit);
      // Fixed point with kShift fraction bits; pixel centres are integers in both conventions.
      point = cv::Point(static_cast<int>(std::lround(x * (1 << kShift))),
                        static_cast<int>(std::lround(y * (1 << kShift))));
    }
    if (!contours)
      throw InputError(fmt::format("{}: contour {} is truncated", contour_path.string(), v));
    cv::Mat mask = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{polygon}, cv::Scalar(255), cv::LINE_8,
                 kShift);
    CameraModel camera = SingleInstantCamera(fmt::format("alien{:02d}", v), mask);
    if (!DecomposeProjection(p, &camera.K, &camera.R, &camera.t))
      throw InputError(
          fmt::format("{}: the projection of camera {} is singular", camera_path.string(), v));
    capture.cameras.push_back(camera);
    capture.masks.push_back(mask);
  }
  return capture;
}

RealCapture LoadTsinghuaWd2(const std::filesystem::path& folder, bool use_distortion) {
  const std::filesystem::path calib = folder / "calibParamsI.txt";
  std::ifstream in = OpenOrThrow(calib, std::ios::in);
  RealCapture capture;
  int index = 0;
  while (in >> index) {
    Eigen::Matrix3d k;
    double d1 = 0, d2 = 0;
    Eigen::Matrix3d r;
    Eigen::Vector3d t;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j)
        in >> k(i, j);
    }
    in >> d1 >> d2;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j)
        in >> r(i, j);
      in >> t(i);
    }
    if (!in)
      throw InputError(fmt::format("{}: camera block {} is malformed", calib.string(), index));
    // The file prints rotations to six decimals: the nearest rotation, and a camera matrix
    // with a positive focal length once scaled to a last element of 1.
    const std::optional<Eigen::Matrix3d> rotation = NearestRotation(r, kPrintedRotationTolerance);
    const Eigen::Matrix3d scaled = k / k(2, 2);
    if (!rotation || !scaled.allFinite() || !(scaled(0, 0) > 0.0 && scaled(1, 1) > 0.0) ||
        !std::isfinite(d1) || !std::isfinite(d2)) {
      throw InputError(
          fmt::format("{}: camera block {} has no valid K or R", calib.string(), index));
    }
    const std::filesystem::path path =
        folder / "silhouettes" / fmt::format("WD2_{}_00020_segmented.png", index);
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw InputError(fmt::format("cannot read {}", path.string()));
    cv::Mat mask;
    cv::threshold(image, mask, 125, 255, cv::THRESH_BINARY);
    CameraModel camera = SingleInstantCamera(fmt::format("wd2_{:02d}", index), mask);
    camera.K = scaled;
    camera.R = *rotation;
    camera.t = t;
    if (use_distortion) {
      camera.dist[0] = d1;
      camera.dist[1] = d2;
    }
    capture.cameras.push_back(camera);
    capture.masks.push_back(mask);
  }
  if (capture.cameras.empty()) throw InputError(fmt::format("{} has no cameras", calib.string()));
  return capture;
}

cv::Mat KeepLargestComponent(const cv::Mat& mask) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask != 0, labels, stats, centroids, 8, CV_32S);
  int best = 0;
  for (int i = 1; i < n; ++i) {
    if (best == 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA))
      best = i;
  }
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8UC1);
  if (best > 0) out.setTo(255, labels == best);
  return out;
}

}  // namespace silnet::aggregator
