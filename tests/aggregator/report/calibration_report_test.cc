#include "aggregator/report/calibration_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "aggregator/report/network_plot.h"
#include "aggregator/report/offset_graph_plot.h"
#include "shared/util/check.h"
#include "tests/aggregator/report/report_test_network.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Fraction of pixels that are not white.
double InkFraction(const cv::Mat& image) {
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return static_cast<double>(cv::countNonZero(grey < 250)) / grey.total();
}

// Pixels that are clearly red (BGR).
int RedPixels(const cv::Mat& image) {
  int count = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      if (p[2] > 150 && p[1] < 90 && p[0] < 90) ++count;
    }
  }
  return count;
}

cv::Mat ReadPng(const std::filesystem::path& path) {
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(image.empty()) << path;
  return image;
}

TEST(CalibrationReport, WritesPageAndReadablePlots) {
  const NetworkCalibration calibration = testing::MakeTestCalibration();
  ::silnet::testing::TempDir dir;
  WriteCalibrationReport(dir / "report", calibration);
  // SILNET_KEEP_REPORT=<folder> keeps a copy to look at.
  if (const char* keep = std::getenv("SILNET_KEEP_REPORT"))
    WriteCalibrationReport(keep, calibration);

  const cv::Mat network = ReadPng(dir / "report/plots/camera_network.png");
  const cv::Mat errors = ReadPng(dir / "report/plots/reprojection_errors.png");
  const cv::Mat offsets = ReadPng(dir / "report/plots/offsets_graph.png");
  EXPECT_EQ(network.size(), cv::Size(1400, 700));
  // 7 placed cameras: a grid of 4 x 2 cells of 350 x 240.
  EXPECT_EQ(errors.size(), cv::Size(4 * 350, 2 * 240));
  EXPECT_EQ(offsets.size(), cv::Size(900, 900));
  for (const cv::Mat* image : {&network, &errors, &offsets}) {
    const double ink = InkFraction(*image);
    EXPECT_GT(ink, 0.01);
    EXPECT_LT(ink, 0.6);
  }
  const std::string html = ReadText(dir / "report/report.html");
  for (const CameraModel& c : calibration.cameras)
    EXPECT_NE(html.find(c.id), std::string::npos);
  EXPECT_NE(html.find(calibration.placement[5].reason), std::string::npos);
  EXPECT_NE(html.find("cycle test: 3 of 4 cycles failed"), std::string::npos);
  EXPECT_NE(html.find("estimate 25 px from the derived F"), std::string::npos);
  EXPECT_NE(html.find("Euclidean bundle adjustment"), std::string::npos);
  EXPECT_NE(html.find("7 of 8"), std::string::npos);
  EXPECT_NE(html.find("self-calibrated"), std::string::npos);
  for (const char* plot :
       {"plots/camera_network.png", "plots/reprojection_errors.png", "plots/offsets_graph.png"})
    EXPECT_NE(html.find(std::string("src=\"") + plot + "\""), std::string::npos) << plot;
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("Ground truth"), std::string::npos);
}

TEST(CalibrationReport, RejectedEdgesAreDrawnRed) {
  const NetworkCalibration calibration = testing::MakeTestCalibration();
  NetworkCalibration all_used = calibration;
  for (SyncEdgeResult& e : all_used.sync.edges) {
    e.used = true;
    e.residual = 0.0;
  }
  // The legend and the unsynchronised camera's label are red in both.
  EXPECT_GT(RedPixels(DrawOffsetGraph(calibration)), RedPixels(DrawOffsetGraph(all_used)) + 100);
}

TEST(CalibrationReport, EscapesHostileStrings) {
  NetworkCalibration calibration = testing::MakeTestCalibration();
  calibration.cameras[0].id = "<script>alert(1)</script>";
  calibration.placement[5].reason = "hull \"clipped\" & <b>empty</b>";
  ::silnet::testing::TempDir dir;
  WriteCalibrationReport(dir.path(), calibration);
  const std::string html = ReadText(dir / "report.html");
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<b>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos);
  EXPECT_NE(html.find("hull &quot;clipped&quot; &amp; &lt;b&gt;empty&lt;/b&gt;"),
            std::string::npos);
}

TEST(CalibrationReport, GroundTruthSection) {
  const NetworkCalibration calibration = testing::MakeTestCalibration();
  CalibrationErrors errors;
  errors.cameras = {{"cam00", 0.004, 0.12, 0.003, 1.5, 0.001, 0.02},
                    {"cam01", 0.006, 0.18, 0.002, 0.7, 0.002, 0.03}};
  errors.rig_diameter = 9.0;
  errors.median_focal_rel = 0.005;
  errors.max_focal_rel = 0.006;
  errors.median_rotation_deg = 0.15;
  errors.max_rotation_deg = 0.18;
  ::silnet::testing::TempDir dir;
  WriteCalibrationReport(dir.path(), calibration, errors);
  const std::string html = ReadText(dir / "report.html");
  const size_t section = html.find("Ground truth");
  ASSERT_NE(section, std::string::npos);
  EXPECT_NE(html.find("0.500", section), std::string::npos);  // median focal error in %
  EXPECT_NE(html.find("0.180", section), std::string::npos);  // max rotation error
  EXPECT_NE(html.find("cam01", section), std::string::npos);
}

TEST(CalibrationReport, EmptyInputsDoNotCrash) {
  testing::TestNetworkOptions options;
  options.network.cameras = 3;
  options.unplaced = {0, 2};  // one placed camera, no points
  NetworkCalibration one = testing::MakeTestCalibration(options);
  one.stages.clear();
  ::silnet::testing::TempDir dir;
  WriteCalibrationReport(dir / "one", one);
  EXPECT_GT(InkFraction(ReadPng(dir / "one/plots/camera_network.png")), 0.005);
  EXPECT_EQ(ReadPng(dir / "one/plots/reprojection_errors.png").size(), cv::Size(350, 240));
  const std::string html = ReadText(dir / "one/report.html");
  EXPECT_NE(html.find("1 of 3"), std::string::npos);

  WriteCalibrationReport(dir / "nothing", NetworkCalibration{});
  EXPECT_TRUE(std::filesystem::exists(dir / "nothing/report.html"));
  EXPECT_FALSE(ReadPng(dir / "nothing/plots/offsets_graph.png").empty());

  // Sync results missing altogether.
  NetworkCalibration no_sync = testing::MakeTestCalibration();
  no_sync.sync = SyncResult{};
  no_sync.points.clear();
  WriteCalibrationReport(dir / "no_sync", no_sync);
  EXPECT_TRUE(std::filesystem::exists(dir / "no_sync/report.html"));
}

TEST(CalibrationReport, UnwritableFolderThrowsInputErrorNamingThePath) {
  ::silnet::testing::TempDir dir;
  std::ofstream(dir / "blocker") << "a file, not a folder";
  const std::filesystem::path target = dir / "blocker" / "report";
  EXPECT_THAT([&] { WriteCalibrationReport(target, testing::MakeTestCalibration()); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(target.string())));
}

// The views' "up" is the world's up for level rigs, whatever the reconstruction's frame.
TEST(NetworkPlot, UpAxisFollowsTheRig) {
  for (sim::RigLayout layout :
       {sim::RigLayout::kRing, sim::RigLayout::kDome, sim::RigLayout::kArc}) {
    for (uint64_t seed : {1, 2, 3}) {
      testing::TestNetworkOptions options;
      options.network.layout = layout;
      options.network.cameras = 10;
      options.network.seed = seed;
      NetworkCalibration calibration = testing::MakeTestCalibration(options);
      // An arbitrary similarity world frame: X' = s Q X + d, so R' = R Q^T, t' = s t - R' d.
      const Eigen::Matrix3d Q =
          Eigen::AngleAxisd(0.3 * seed + 0.7, Eigen::Vector3d(1, 2, 3).normalized())
              .toRotationMatrix();
      const double s = 0.37;
      const Eigen::Vector3d d(5, -2, 1);
      for (CameraModel& c : calibration.cameras) {
        c.R = c.R * Q.transpose();
        c.t = s * c.t - c.R * d;
      }
      const ViewFrame frame = NetworkViewFrame(calibration);
      const Eigen::Vector3d up = Q * Eigen::Vector3d::UnitZ();
      // The camera heights are jittered (elevations +-6 degrees), so the best-fit plane of
      // the centres tilts by a few degrees.
      EXPECT_GT(frame.up.dot(up), std::cos(12.0 * std::numbers::pi / 180))
          << sim::ToString(layout) << seed;
      EXPECT_NEAR(frame.horizontal.dot(frame.up), 0.0, 1e-9);
      EXPECT_NEAR(frame.across.dot(frame.up), 0.0, 1e-9);
      EXPECT_NEAR(frame.horizontal.cross(frame.across).dot(frame.up), 1.0, 1e-9);
    }
  }
}

}  // namespace
}  // namespace silnet::aggregator
