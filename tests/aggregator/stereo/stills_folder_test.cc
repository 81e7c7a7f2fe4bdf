// Loading stills folders written in a temporary folder: the good case, cameras missing on
// either side, broken files, non-binary masks, the background fallback and the errors.

#include "aggregator/stereo/stills_folder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "aggregator/stereo/undistort_view.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64;
constexpr int kHeight = 48;

CameraModel Camera(const std::string& id) {
  CameraModel camera;
  camera.id = id;
  camera.width = kWidth;
  camera.height = kHeight;
  camera.K << 60, 0, 31.5, 0, 60, 23.5, 0, 0, 1;
  camera.t = Eigen::Vector3d(0, 0, 2);
  return camera;
}

// A textured BGR image, different per seed.
cv::Mat Texture(int seed, cv::Size size = {kWidth, kHeight}) {
  cv::Mat image(size, CV_8UC3);
  cv::RNG rng(static_cast<uint64_t>(seed) + 1);
  rng.fill(image, cv::RNG::UNIFORM, cv::Scalar::all(40), cv::Scalar::all(200));
  return image;
}

// A disc silhouette.
cv::Mat Disc(cv::Size size = {kWidth, kHeight}) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  cv::circle(mask, {size.width / 2, size.height / 2}, size.height / 3, cv::Scalar(255), cv::FILLED);
  return mask;
}

void Write(const fs::path& path, const cv::Mat& image) {
  fs::create_directories(path.parent_path());
  ASSERT_TRUE(cv::imwrite(path.string(), image)) << path;
}

// A stills folder of cameras cam0..cam{n-1}: still 0 and its mask each, and calibration.yaml.
struct Folder {
  silnet::testing::TempDir dir;
  fs::path calibration;
  std::vector<CameraModel> cameras;

  explicit Folder(int n) {
    for (int c = 0; c < n; ++c) {
      cameras.push_back(Camera("cam" + std::to_string(c)));
      Write(Still(c), Texture(c));
      Write(Mask(c), Disc());
    }
    calibration = dir / "calibration.yaml";
    SaveCalibration(calibration, cameras);
  }
  fs::path Still(int c, const std::string& frame = "000000.png") const {
    return dir / ("cam" + std::to_string(c)) / "stills" / frame;
  }
  fs::path Mask(int c, const std::string& frame = "000000.png") const {
    return dir / ("cam" + std::to_string(c)) / "masks" / frame;
  }
  StereoViews Load(const StillsFolderOptions& options = {}) const {
    return LoadStillsFolder(dir.path(), calibration, options);
  }
};

// True if `warnings` has one line holding both `a` and `b`.
bool HasWarning(const std::vector<std::string>& warnings, const std::string& a,
                const std::string& b) {
  for (const std::string& w : warnings) {
    if (w.find(a) != std::string::npos && w.find(b) != std::string::npos) return true;
  }
  return false;
}

TEST(StillsFolderTest, LoadsEveryCameraWithItsStillAndMask) {
  const Folder folder(3);
  const StereoViews views = folder.Load();
  EXPECT_TRUE(views.warnings.empty());
  ASSERT_EQ(views.views.size(), 3u);
  for (int c = 0; c < 3; ++c) {
    const StereoView& view = views.views[static_cast<size_t>(c)];
    EXPECT_EQ(view.camera.id, "cam" + std::to_string(c));
    EXPECT_EQ(view.silhouette_source, MaskOrigin::kMaskFile);
    EXPECT_EQ(view.nonbinary_mask_pixels, 0u);
    EXPECT_EQ(cv::norm(view.image, Texture(c), cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(view.mask, Disc(), cv::NORM_INF), 0);
  }
}

TEST(StillsFolderTest, TakesTheRequestedStill) {
  const Folder folder(2);
  for (int c = 0; c < 2; ++c) {
    Write(folder.Still(c, "000003.png"), Texture(10 + c));
    Write(folder.Mask(c, "000003.png"), Disc());
  }
  StillsFolderOptions options;
  options.frame = 3;
  const StereoViews views = folder.Load(options);
  ASSERT_EQ(views.views.size(), 2u);
  EXPECT_EQ(cv::norm(views.views[1].image, Texture(11), cv::NORM_INF), 0);
}

TEST(StillsFolderTest, ReportsAndLeavesOutACalibratedCameraWithoutStills) {
  Folder folder(3);
  folder.cameras.push_back(Camera("cam9"));
  SaveCalibration(folder.calibration, folder.cameras);
  const StereoViews views = folder.Load();
  EXPECT_EQ(views.views.size(), 3u);
  ASSERT_EQ(views.warnings.size(), 1u);
  EXPECT_TRUE(HasWarning(views.warnings, "cam9", "no still")) << views.warnings[0];
}

TEST(StillsFolderTest, ReportsAndLeavesOutStillsWithoutACamera) {
  const Folder folder(3);
  Write(folder.dir / "extra" / "stills" / "000000.png", Texture(5));
  const StereoViews views = folder.Load();
  EXPECT_EQ(views.views.size(), 3u);
  ASSERT_EQ(views.warnings.size(), 1u);
  EXPECT_TRUE(HasWarning(views.warnings, "extra", "no camera")) << views.warnings[0];
}

TEST(StillsFolderTest, ReportsAndLeavesOutImagesOfTheWrongSize) {
  const Folder folder(4);
  Write(folder.Still(1), Texture(1, {32, 24}));
  Write(folder.Mask(2), Disc({32, 24}));
  const StereoViews views = folder.Load();
  ASSERT_EQ(views.views.size(), 2u);
  EXPECT_EQ(views.views[1].camera.id, "cam3");
  EXPECT_TRUE(HasWarning(views.warnings, "cam1", "is 32x24")) << views.warnings[0];
  EXPECT_TRUE(HasWarning(views.warnings, "cam2", "the calibration says 64x48"));
}

TEST(StillsFolderTest, ReportsAndLeavesOutCorruptPngs) {
  const Folder folder(3);
  {
    const std::string garbage = "\x89PNG\r\n\x1a\n this is not a PNG stream";
    std::ofstream(folder.Still(2), std::ios::binary) << garbage;
  }
  const StereoViews views = folder.Load();
  EXPECT_EQ(views.views.size(), 2u);
  ASSERT_EQ(views.warnings.size(), 1u);
  EXPECT_TRUE(HasWarning(views.warnings, "cam2", "cannot read or decode")) << views.warnings[0];
}

TEST(StillsFolderTest, ThresholdsAndCountsNonBinaryMaskValues) {
  const Folder folder(2);
  cv::Mat mask = Disc();
  mask(cv::Rect(0, 0, 4, 2)).setTo(200);    // 8 pixels outside the disc: become silhouette
  mask(cv::Rect(28, 22, 3, 1)).setTo(100);  // 3 pixels inside it: become background
  Write(folder.Mask(1), mask);
  const StereoViews views = folder.Load();
  ASSERT_EQ(views.views.size(), 2u);
  const StereoView& view = views.views[1];
  EXPECT_EQ(view.nonbinary_mask_pixels, 11u);
  EXPECT_EQ(view.mask.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(view.mask.at<uint8_t>(22, 29), 0);
  EXPECT_EQ(cv::countNonZero(view.mask), cv::countNonZero(Disc()) + 8 - 3);
  EXPECT_TRUE(HasWarning(views.warnings, "cam1", "11 mask pixels")) << views.warnings.size();
}

TEST(StillsFolderTest, SegmentsACameraWithoutMasksAgainstItsBackground) {
  const Folder folder(3);
  const cv::Mat background = Texture(7);
  cv::Mat still = background.clone();
  const cv::Rect subject(20, 12, 24, 24);
  still(subject).setTo(cv::Scalar(20, 230, 60));
  Write(folder.Still(1), still);
  Write(folder.dir / "cam1" / "background.png", background);
  fs::remove(folder.Mask(1));
  const StereoViews views = folder.Load();
  ASSERT_EQ(views.views.size(), 3u);
  EXPECT_TRUE(views.warnings.empty());
  const StereoView& view = views.views[1];
  EXPECT_EQ(view.silhouette_source, MaskOrigin::kBackgroundDifference);
  cv::Mat expected = cv::Mat::zeros(still.size(), CV_8UC1);
  expected(subject).setTo(255);
  // The node's opening rounds the square's corners: a pixel or two each.
  EXPECT_LE(cv::norm(view.mask, expected, cv::NORM_L1) / 255, 8) << "pixels differing";
}

TEST(StillsFolderTest, StopsWhenACameraHasNeitherMasksNorBackground) {
  const Folder folder(3);
  fs::remove_all(folder.dir / "cam2" / "masks");
  EXPECT_THAT([&] { folder.Load(); },
              ::testing::ThrowsMessage<InputError>(::testing::AllOf(
                  ::testing::HasSubstr("camera cam2 has no silhouette"),
                  ::testing::HasSubstr((fs::path("cam2") / "masks" / "000000.png").string()),
                  ::testing::HasSubstr((fs::path("cam2") / "background.png").string()))));
}

TEST(StillsFolderTest, StopsWithFewerThanTwoUsableCameras) {
  const Folder folder(2);
  fs::remove(folder.Still(0));
  EXPECT_THAT([&] { folder.Load(); },
              ::testing::ThrowsMessage<InputError>(::testing::AllOf(
                  ::testing::HasSubstr("1 usable camera(s), stereo needs at least 2"),
                  ::testing::HasSubstr("cam0: no still"))));
}

TEST(StillsFolderTest, RejectsInvalidOptionsAndAMissingCalibration) {
  const Folder folder(2);
  StillsFolderOptions options;
  options.frame = -1;
  EXPECT_THROW(folder.Load(options), InputError);
  EXPECT_THROW(LoadStillsFolder(folder.dir.path(), folder.dir / "none.yaml"), InputError);
}

// Distorted cameras become pinhole views: a dot at a distorted pixel moves to where the
// camera model undistorts that pixel.
TEST(StillsFolderTest, RemovesLensDistortion) {
  Folder folder(2);
  folder.cameras[1].dist << 0.8, 0, 0.001, -0.002, 0;
  SaveCalibration(folder.calibration, folder.cameras);
  const Eigen::Vector2d distorted(56, 40);
  cv::Mat dot = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  cv::circle(dot, {56, 40}, 2, cv::Scalar(255), cv::FILLED);
  Write(folder.Mask(1), dot);
  const StereoViews views = folder.Load();
  ASSERT_EQ(views.views.size(), 2u);
  const StereoView& view = views.views[1];
  EXPECT_FALSE(view.camera.HasDistortion());
  const Eigen::Vector2d expected = folder.cameras[1].UndistortPixel(distorted);
  ASSERT_GT((expected - distorted).norm(), 2.5);  // the test moves the dot noticeably
  const cv::Moments m = cv::moments(view.mask, true);
  ASSERT_GT(m.m00, 0);
  EXPECT_NEAR(m.m10 / m.m00, expected.x(), 0.5);
  EXPECT_NEAR(m.m01 / m.m00, expected.y(), 0.5);

  StillsFolderOptions keep;
  keep.undistort = false;
  EXPECT_TRUE(folder.Load(keep).views[1].camera.HasDistortion());
}

}  // namespace
}  // namespace silnet::aggregator
