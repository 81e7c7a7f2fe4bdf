#include <gtest/gtest.h>

#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"
#include "tests/sim/reference_raster.h"

namespace silnet::sim {
namespace {

struct Fixture {
  std::vector<CameraModel> cameras;
  std::unique_ptr<Scene> scene;
};

Fixture MakeFixture(double distortion, int width, int height,
                    SubjectKind kind = SubjectKind::kHuman) {
  CameraNetworkOptions network;
  network.cameras = 4;
  network.width = width;
  network.height = height;
  network.max_distortion = distortion;
  network.seed = 21;
  SceneOptions scene;
  scene.subject = kind;
  scene.seed = 21;
  scene.time_begin = -1;
  scene.time_end = 30;
  return {MakeCameraNetwork(network), std::make_unique<Scene>(scene)};
}

// Rendered masks agree with the independent rasteriser (IoU >= 0.99, in fact ~1).
void ExpectMasksMatchReference(double distortion) {
  const Fixture f = MakeFixture(distortion, 320, 240);
  RenderSettings settings;
  for (size_t c = 0; c < f.cameras.size(); ++c) {
    const CameraRenderer renderer(f.cameras[c], *f.scene, settings, static_cast<int>(c));
    for (double time : {0.5, 4.0, 9.3}) {
      cv::Mat mask;
      renderer.Render(time, 0, &mask, nullptr);
      const cv::Mat reference = testing::ReferenceMask(f.cameras[c], f.scene->PrimitivesAt(time));
      ASSERT_GT(cv::countNonZero(reference), 200) << "subject not in view";
      EXPECT_GE(testing::MaskIoU(mask, reference), 0.99) << f.cameras[c].id << " t=" << time;
      EXPECT_LE(cv::countNonZero(mask != reference), 3) << f.cameras[c].id << " t=" << time;
    }
  }
}

TEST(CameraRenderer, MasksMatchTheProjectedGeometry) {
  ExpectMasksMatchReference(0.0);
}

TEST(CameraRenderer, MasksMatchTheProjectedGeometryWithRadialDistortion) {
  ExpectMasksMatchReference(0.1);
}

TEST(CameraRenderer, ProjectedSurfacePointsFallOnTheSilhouette) {
  const Fixture f = MakeFixture(0.08, 640, 480);
  std::mt19937_64 rng(3);
  size_t total = 0, outside = 0;
  for (size_t c = 0; c < f.cameras.size(); ++c) {
    const CameraModel& cam = f.cameras[c];
    const CameraRenderer renderer(cam, *f.scene, RenderSettings{}, static_cast<int>(c));
    cv::Mat mask;
    const double time = 2.0 + static_cast<double>(c);
    renderer.Render(time, 0, &mask, nullptr);
    cv::Mat K, dist, R, rvec;
    cv::eigen2cv(cam.K, K);
    cv::eigen2cv(Eigen::Matrix<double, 1, 5>(cam.dist.transpose()), dist);
    cv::eigen2cv(cam.R, R);
    cv::Rodrigues(R, rvec);
    const cv::Mat tvec = (cv::Mat_<double>(3, 1) << cam.t.x(), cam.t.y(), cam.t.z());
    std::vector<cv::Point3d> points;
    for (const Primitive& p : f.scene->PrimitivesAt(time)) {
      for (const Eigen::Vector3d& x : p.SampleSurface(300, rng))
        points.emplace_back(x.x(), x.y(), x.z());
    }
    std::vector<cv::Point2d> projected;
    cv::projectPoints(points, rvec, tvec, K, dist, projected);
    for (const cv::Point2d& p : projected) {
      const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y));
      if (x < 1 || y < 1 || x >= cam.width - 1 || y >= cam.height - 1) continue;
      ++total;
      // A point on the outline may round to a background pixel: allow a 1-pixel ring.
      if (cv::countNonZero(mask(cv::Rect(x - 1, y - 1, 3, 3))) == 0) ++outside;
    }
  }
  EXPECT_GT(total, 5000u);
  EXPECT_EQ(outside, 0u);
}

TEST(CameraRenderer, ColourFramesShowTheSubjectShadowsLightChangesAndNoise) {
  const Fixture f = MakeFixture(0.0, 320, 240);
  RenderSettings settings;
  settings.noise_sigma = 2.0;
  const CameraRenderer renderer(f.cameras[0], *f.scene, settings, 0);
  cv::Mat mask, colour, empty_colour, colour2;
  renderer.Render(3.0, 1, &mask, &colour);
  renderer.RenderPrimitives({}, f.scene->environment().LightGain(3.0), 2, nullptr, &empty_colour);
  renderer.Render(3.0, 3, nullptr, &colour2);
  cv::Mat diff, diff_gray;
  cv::absdiff(colour, empty_colour, diff);
  cv::cvtColor(diff, diff_gray, cv::COLOR_BGR2GRAY);
  const cv::Scalar inside = cv::mean(diff_gray, mask);
  const cv::Scalar outside = cv::mean(diff_gray, ~mask);
  EXPECT_GT(inside[0], 20.0);  // the subject differs from the room
  EXPECT_LT(outside[0], 6.0);  // elsewhere noise and shadow only
  // Shadows: a patch of background pixels darkened well beyond noise.
  const cv::Mat darker = (diff_gray > 25) & ~mask;
  EXPECT_GT(cv::countNonZero(darker), 50);
  // Noise: two renders of the same instant differ by about sigma * sqrt(2) per channel.
  cv::Mat a, b;
  colour.convertTo(a, CV_32F);
  colour2.convertTo(b, CV_32F);
  cv::Scalar mean, stddev;
  const cv::Mat difference = a - b;
  cv::meanStdDev(difference.reshape(1), mean, stddev);
  EXPECT_NEAR(stddev[0], 2.0 * std::sqrt(2.0), 0.4);
  // Lighting changes over time: mean brightness of the room varies by a few percent.
  double low = 1e9, high = 0;
  for (double t = 0; t < 10; t += 0.5) {
    cv::Mat room;
    renderer.RenderPrimitives({}, f.scene->environment().LightGain(t), 4, nullptr, &room);
    const double m = cv::mean(room)[0];
    low = std::min(low, m);
    high = std::max(high, m);
  }
  EXPECT_GT(high / low, 1.03);
}

TEST(CameraRenderer, TheSubjectSometimesLeavesPartOfAView) {
  const Fixture f = [] {
    Fixture fixture;
    CameraNetworkOptions network;
    network.width = 160;
    network.height = 120;
    network.seed = 1;
    fixture.cameras = MakeCameraNetwork(network);
    SceneOptions scene;
    scene.time_begin = -1;
    scene.time_end = 21;
    fixture.scene = std::make_unique<Scene>(scene);
    return fixture;
  }();
  int clipped = 0, empty = 0, total = 0;
  for (size_t c = 0; c < f.cameras.size(); ++c) {
    const CameraRenderer renderer(f.cameras[c], *f.scene, RenderSettings{}, static_cast<int>(c));
    for (int k = 0; k < 600; k += 2) {
      cv::Mat mask;
      renderer.Render(f.cameras[c].ExposureTime(k), 0, &mask, nullptr);
      ++total;
      if (cv::countNonZero(mask) == 0) ++empty;
      const bool touches =
          cv::countNonZero(mask.row(0)) + cv::countNonZero(mask.row(mask.rows - 1)) +
              cv::countNonZero(mask.col(0)) + cv::countNonZero(mask.col(mask.cols - 1)) >
          0;
      if (touches) ++clipped;
    }
  }
  std::printf("clipped %d, empty %d of %d masks\n", clipped, empty, total);
  EXPECT_GT(clipped, total / 100) << "never clipped";
  EXPECT_LT(clipped, total / 2) << "clipped most of the time";
  EXPECT_LT(empty, total / 50);
}

}  // namespace
}  // namespace silnet::sim
