#include "aggregator/report/colmap_export.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "shared/util/check.h"
#include "tests/aggregator/report/report_test_network.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

// A minimal reader of COLMAP's text model, written from the format documentation.
struct ColmapCamera {
  std::string model;
  int width = 0, height = 0;
  std::vector<double> params;
};
struct ColmapImage {
  double qw = 0, qx = 0, qy = 0, qz = 0;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  int camera_id = 0;
  std::string name;
  std::vector<Eigen::Vector2d> xy;
  std::vector<long> point3d_ids;
};
struct ColmapPoint {
  Eigen::Vector3d X = Eigen::Vector3d::Zero();
  double error = 0.0;
  std::vector<std::pair<int, size_t>> track;  // (IMAGE_ID, POINT2D_IDX)
};
struct ColmapModel {
  std::map<int, ColmapCamera> cameras;
  std::map<int, ColmapImage> images;
  std::map<long, ColmapPoint> points;
};

// Data lines of a file (comments skipped; empty lines kept, images.txt needs them).
std::vector<std::string> DataLines(const std::filesystem::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') continue;
    lines.push_back(line);
  }
  return lines;
}

ColmapModel ReadColmap(const std::filesystem::path& dir) {
  ColmapModel model;
  for (const std::string& line : DataLines(dir / "cameras.txt")) {
    if (line.empty()) continue;
    std::istringstream s(line);
    int id = 0;
    ColmapCamera c;
    s >> id >> c.model >> c.width >> c.height;
    for (double v; s >> v;)
      c.params.push_back(v);
    EXPECT_TRUE(model.cameras.emplace(id, c).second) << "duplicate camera " << id;
  }
  const std::vector<std::string> lines = DataLines(dir / "images.txt");
  EXPECT_EQ(lines.size() % 2, 0u);
  for (size_t k = 0; k + 1 < lines.size(); k += 2) {
    std::istringstream s(lines[k]);
    int id = 0;
    ColmapImage image;
    s >> id >> image.qw >> image.qx >> image.qy >> image.qz >> image.t.x() >> image.t.y() >>
        image.t.z() >> image.camera_id >> image.name;
    EXPECT_FALSE(s.fail()) << lines[k];
    std::istringstream p(lines[k + 1]);
    double x = 0, y = 0;
    long point = 0;
    while (p >> x >> y >> point) {
      image.xy.emplace_back(x, y);
      image.point3d_ids.push_back(point);
    }
    EXPECT_TRUE(model.images.emplace(id, image).second) << "duplicate image " << id;
  }
  for (const std::string& line : DataLines(dir / "points3D.txt")) {
    if (line.empty()) continue;
    std::istringstream s(line);
    long id = 0;
    int r = 0, g = 0, b = 0;
    ColmapPoint point;
    s >> id >> point.X.x() >> point.X.y() >> point.X.z() >> r >> g >> b >> point.error;
    EXPECT_FALSE(s.fail()) << line;
    int image = 0;
    size_t index = 0;
    while (s >> image >> index)
      point.track.emplace_back(image, index);
    EXPECT_TRUE(model.points.emplace(id, point).second) << "duplicate point " << id;
  }
  return model;
}

// COLMAP's projection (models PINHOLE, OPENCV, FULL_OPENCV) in COLMAP's pixel convention.
Eigen::Vector2d ColmapProject(const ColmapCamera& c, const ColmapImage& image,
                              const Eigen::Vector3d& X) {
  const double w = image.qw, x = image.qx, y = image.qy, z = image.qz;
  Eigen::Matrix3d R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),  //
      2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),   //
      2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y);
  const Eigen::Vector3d cam = R * X + image.t;
  const double u = cam.x() / cam.z(), v = cam.y() / cam.z();
  const std::vector<double>& p = c.params;
  double du = 0.0, dv = 0.0;
  if (c.model != "PINHOLE") {
    const double r2 = u * u + v * v;
    double radial = 1.0 + p[4] * r2 + p[5] * r2 * r2;
    if (c.model == "FULL_OPENCV") {
      radial = (radial + p[8] * r2 * r2 * r2) /
               (1.0 + p[9] * r2 + p[10] * r2 * r2 + p[11] * r2 * r2 * r2);
    }
    du = u * (radial - 1.0) + 2 * p[6] * u * v + p[7] * (r2 + 2 * u * u);
    dv = v * (radial - 1.0) + 2 * p[7] * u * v + p[6] * (r2 + 2 * v * v);
  }
  return {p[0] * (u + du) + p[2], p[1] * (v + dv) + p[3]};
}

size_t ExpectedParams(const std::string& model) {
  if (model == "PINHOLE") return 4;
  if (model == "OPENCV") return 8;
  if (model == "FULL_OPENCV") return 12;
  ADD_FAILURE() << "unexpected model " << model;
  return 0;
}

TEST(ColmapExport, ParsesBackToTheSameCamerasPosesAndTracks) {
  for (uint64_t seed : {1, 2, 3}) {
    testing::TestNetworkOptions options;
    options.network.seed = seed;
    options.network.max_distortion = 0.08;
    options.seed = seed;
    NetworkCalibration calibration = testing::MakeTestCalibration(options);
    calibration.cameras[1].dist.setZero();  // PINHOLE
    calibration.cameras[2].dist[4] = 0.01;  // k3: FULL_OPENCV
    calibration.cameras[3].dist[2] = 1e-3;  // tangential terms
    calibration.cameras[3].dist[3] = -2e-3;
    calibration.cameras[4].id = "left\tcam 4";  // white space would split the line
    ::silnet::testing::TempDir dir;
    WriteColmapText(dir.path(), calibration);
    const ColmapModel model = ReadColmap(dir.path());

    // Placed cameras only, ids = index + 1.
    ASSERT_EQ(model.cameras.size(), calibration.PlacedCount());
    ASSERT_EQ(model.images.size(), calibration.PlacedCount());
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    for (size_t i = 0; i < calibration.cameras.size(); ++i) {
      const int id = static_cast<int>(i) + 1;
      if (!calibration.placement[i].placed) {
        EXPECT_EQ(model.cameras.count(id), 0u);
        EXPECT_EQ(model.images.count(id), 0u);
        continue;
      }
      const CameraModel& truth = calibration.cameras[i];
      ASSERT_EQ(model.cameras.count(id), 1u);
      ASSERT_EQ(model.images.count(id), 1u);
      const ColmapCamera& c = model.cameras.at(id);
      const ColmapImage& image = model.images.at(id);
      EXPECT_EQ(c.model, i == 1 ? "PINHOLE" : i == 2 ? "FULL_OPENCV" : "OPENCV") << truth.id;
      ASSERT_EQ(c.params.size(), ExpectedParams(c.model));
      EXPECT_EQ(c.width, truth.width);
      EXPECT_EQ(c.height, truth.height);
      EXPECT_DOUBLE_EQ(c.params[0], truth.K(0, 0));
      EXPECT_DOUBLE_EQ(c.params[1], truth.K(1, 1));
      EXPECT_DOUBLE_EQ(c.params[2], truth.K(0, 2) + 0.5);
      EXPECT_DOUBLE_EQ(c.params[3], truth.K(1, 2) + 0.5);
      if (c.model != "PINHOLE") {
        for (int k = 0; k < 4; ++k)
          EXPECT_DOUBLE_EQ(c.params[4 + k], truth.dist[k]);
      }
      EXPECT_EQ(image.camera_id, id);
      EXPECT_EQ(image.name, i == 4 ? "left_cam_4.png" : truth.id + ".png");
      EXPECT_NEAR(
          image.qw * image.qw + image.qx * image.qx + image.qy * image.qy + image.qz * image.qz,
          1.0, 1e-12);
      // The parsed pose and intrinsics project like silnet's model, half a pixel apart.
      for (int k = 0; k < 50; ++k) {
        const Eigen::Vector3d X(uniform(rng), uniform(rng), 0.9 + 0.8 * uniform(rng));
        const Eigen::Vector2d silnet_pixel = truth.Project(X).value();
        const Eigen::Vector2d colmap_pixel = ColmapProject(c, image, X);
        EXPECT_LT((colmap_pixel - silnet_pixel - Eigen::Vector2d(0.5, 0.5)).norm(), 1e-8)
            << truth.id;
      }
    }

    // Points: every inlier, with its two observations as a track.
    std::vector<const FrontierPoint*> inliers;
    for (const FrontierPoint& p : calibration.points) {
      if (p.inlier) inliers.push_back(&p);
    }
    ASSERT_EQ(model.points.size(), inliers.size());
    size_t k = 0;
    for (const auto& [id, point] : model.points) {
      const FrontierPoint& truth = *inliers[k++];
      EXPECT_EQ(id, static_cast<long>(k));
      EXPECT_LT((point.X - truth.X).norm(), 1e-12);
      EXPECT_NEAR(point.error, 0.5 * (truth.views[0].error_px + truth.views[1].error_px), 1e-12);
      ASSERT_EQ(point.track.size(), 2u);
      for (int v = 0; v < 2; ++v) {
        const auto [image_id, index] = point.track[v];
        EXPECT_EQ(image_id, static_cast<int>(truth.views[v].camera) + 1);
        ASSERT_EQ(model.images.count(image_id), 1u);
        const ColmapImage& image = model.images.at(image_id);
        ASSERT_LT(index, image.xy.size());
        EXPECT_EQ(image.point3d_ids[index], id);
        EXPECT_LT((image.xy[index] - truth.views[v].pixel - Eigen::Vector2d(0.5, 0.5)).norm(),
                  1e-9);
      }
    }
    // Every observation refers to an existing point whose track points back to it.
    size_t observations = 0;
    for (const auto& [image_id, image] : model.images) {
      for (size_t index = 0; index < image.point3d_ids.size(); ++index) {
        ++observations;
        ASSERT_EQ(model.points.count(image.point3d_ids[index]), 1u);
        const auto& track = model.points.at(image.point3d_ids[index]).track;
        EXPECT_NE(std::find(track.begin(), track.end(), std::make_pair(image_id, index)),
                  track.end());
      }
    }
    EXPECT_EQ(observations, 2 * inliers.size());
  }
}

TEST(ColmapExport, EmptyInputsGiveValidFiles) {
  testing::TestNetworkOptions options;
  options.network.cameras = 3;
  options.unplaced = {0, 2};  // one placed camera, hence no points
  const NetworkCalibration calibration = testing::MakeTestCalibration(options);
  ASSERT_TRUE(calibration.points.empty());
  ::silnet::testing::TempDir dir;
  WriteColmapText(dir / "model", calibration);
  const ColmapModel model = ReadColmap(dir / "model");
  ASSERT_EQ(model.cameras.size(), 1u);
  ASSERT_EQ(model.images.size(), 1u);
  EXPECT_EQ(model.images.begin()->first, 2);
  EXPECT_TRUE(model.images.begin()->second.xy.empty());
  EXPECT_TRUE(model.points.empty());

  WriteColmapText(dir / "nothing", NetworkCalibration{});
  EXPECT_TRUE(ReadColmap(dir / "nothing").cameras.empty());
}

TEST(ColmapExport, UnwritableFolderThrowsInputErrorNamingThePath) {
  ::silnet::testing::TempDir dir;
  std::ofstream(dir / "blocker") << "a file, not a folder";
  const std::filesystem::path target = dir / "blocker" / "model";
  EXPECT_THAT([&] { WriteColmapText(target, testing::MakeTestCalibration()); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(target.string())));
}

}  // namespace
}  // namespace silnet::aggregator
