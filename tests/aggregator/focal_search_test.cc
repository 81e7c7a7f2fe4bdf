// The focal length search (aggregator/calibration/focal_search.h) on exact correspondences of
// four cameras whose principal points lie off the image centres the search assumes: the
// relative rotations then close only approximately, and a tolerance tighter than that leaves
// the first search without a start and the second, looser one with the true focal length.

#include "aggregator/calibration/focal_search.h"

#include <gtest/gtest.h>

#include <random>

#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

constexpr double kFocal = 800.0;  // px, 1.25 x the larger side of 640 x 480

// Four cameras around the origin, principal points 25-40 px off centre.
std::vector<CameraModel> TrueCameras() {
  const Eigen::Vector3d centres[4] = {{4, 0, 1}, {0, 4, 1.3}, {-4, 0.5, 0.8}, {0.3, -4, 1.1}};
  const Eigen::Vector2d principal_offsets[4] = {{30, -25}, {-35, 20}, {25, 30}, {-30, -40}};
  std::vector<CameraModel> cameras(4);
  for (size_t k = 0; k < 4; ++k) {
    CameraModel& c = cameras[k];
    c.id = "cam" + std::to_string(k);
    c.width = 640;
    c.height = 480;
    c.K << kFocal, 0, 319.5 + principal_offsets[k].x(), 0, kFocal, 239.5 + principal_offsets[k].y(),
        0, 0, 1;
    c.R = LookAtRotation(centres[k], Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    c.t = -c.R * centres[k];
  }
  return cameras;
}

// Every pair ok, with F and 200 exact correspondences of points in the working volume.
std::vector<PairwiseResult> ExactPairs(const std::vector<CameraModel>& cameras) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coordinate(-0.8, 0.8);
  std::vector<Eigen::Vector3d> points(200);
  for (Eigen::Vector3d& p : points)
    p = {coordinate(rng), coordinate(rng), coordinate(rng) + 0.8};
  std::vector<PairwiseResult> pairs;
  for (size_t i = 0; i < cameras.size(); ++i) {
    for (size_t j = i + 1; j < cameras.size(); ++j) {
      PairwiseResult p;
      p.camera_i = cameras[i].id;
      p.camera_j = cameras[j].id;
      p.status = PairStatus::kOk;
      p.F = FundamentalFromCameras(cameras[i], cameras[j]);
      for (size_t k = 0; k < points.size(); ++k) {
        TimedMatch m;
        m.x_i = *cameras[i].Project(points[k]);
        m.x_j_a = m.x_j_b = *cameras[j].Project(points[k]);
        m.frame_i = m.frame_j = k;
        p.inlier_matches.push_back(m);
      }
      p.inliers = p.inlier_matches.size();
      pairs.push_back(p);
    }
  }
  return pairs;
}

TEST(FocalSearch, SearchesAgainWithALooserToleranceWhenNothingAgrees) {
  const std::vector<CameraModel> truth = TrueCameras();
  const std::vector<PairwiseResult> pairs = ExactPairs(truth);
  std::vector<CameraModel> templates = truth;
  for (CameraModel& c : templates)
    c.K = Eigen::Matrix3d::Identity();

  GlobalStartOptions tight;
  tight.rotation_tolerance_deg = 0.1;
  FocalSearchOptions once;
  once.fallback_tolerance_factor = 1.0;
  const FocalSearchResult first = SearchCommonFocal(templates, pairs, once, tight);
  EXPECT_FALSE(first.ok);
  EXPECT_NE(first.detail.find("within 0.1 deg"), std::string::npos) << first.detail;

  FocalSearchOptions twice;
  twice.fallback_tolerance_factor = 30.0;  // 3 deg
  const FocalSearchResult second = SearchCommonFocal(templates, pairs, twice, tight);
  ASSERT_TRUE(second.ok) << second.detail;
  EXPECT_NE(second.detail.find("within 3.0 deg: none agreed within 0.1"), std::string::npos)
      << second.detail;
  // The steps of the search are 11 % apart: the nearest one to the truth.
  EXPECT_NEAR(second.factor, kFocal / 640.0, 0.06 * kFocal / 640.0) << second.detail;
  EXPECT_EQ(second.cameras.size(), 4u);
}

}  // namespace
}  // namespace silnet::aggregator
