// Photo-consistency (thesis 6.8.1): its parts (neighbour choice, NCC windows against OpenCV,
// epipolar rays, sub-pixel maxima) and the whole on simulated stills against the true
// surface: where the votes lie, where the maxima along viewing rays lie, and that in
// concavities the hull fills they lie at the truth, not at the hull.

#include "aggregator/stereo/photo_consistency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>

#include "aggregator/hulls/mesh_measure.h"
#include "shared/util/check.h"
#include "sim/camera_network.h"
#include "tests/aggregator/stereo/simulated_stills.h"
#include "tests/aggregator/stereo/vote_evaluation.h"

namespace silnet::aggregator {
namespace {

using testing::NearestPoint;

// A smooth random texture, CV_8UC3 BGR.
cv::Mat RandomTexture(int width, int height, uint64_t seed) {
  cv::Mat noise(height, width, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 1.5);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

StereoView ViewOf(const cv::Mat& image) {
  StereoView view;
  view.image = image;
  view.mask = cv::Mat(image.size(), CV_8UC1, cv::Scalar(255));
  return view;
}

TEST(NeighbourViewsTest, RingNeighboursAreTheAdjacentCamerasByAngle) {
  sim::CameraNetworkOptions network;
  network.cameras = 16;
  const std::vector<CameraModel> cameras = sim::MakeCameraNetwork(network);
  const auto neighbours = SelectNeighbourViews(cameras, Eigen::Vector3d(0, 0, 0.95));
  ASSERT_EQ(neighbours.size(), 16u);
  for (int c = 0; c < 16; ++c) {
    ASSERT_EQ(neighbours[c].size(), 4u);
    // 22.5 degrees apart (with aim jitter) first, then 45.
    const std::set<int> first = {neighbours[c][0], neighbours[c][1]};
    const std::set<int> second = {neighbours[c][2], neighbours[c][3]};
    EXPECT_EQ(first, (std::set<int>{(c + 1) % 16, (c + 15) % 16})) << c;
    EXPECT_EQ(second, (std::set<int>{(c + 2) % 16, (c + 14) % 16})) << c;
  }
  NeighbourViewOptions narrow;
  narrow.max_angle_deg = 10.0;
  EXPECT_TRUE(SelectNeighbourViews(cameras, Eigen::Vector3d(0, 0, 0.95), narrow)[0].empty());
  narrow.min_angle_deg = 20.0;
  EXPECT_FALSE(narrow.Validate().empty());
}

// At integer centres the grey windowed NCC is OpenCV's TM_CCOEFF_NORMED (in colour, OpenCV
// removes a mean per channel and the matcher one over all channels: only self-similarity).
TEST(EpipolarNccTest, WindowNccMatchesOpenCvAtIntegerPositions) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    for (bool colour : {false, true}) {
      EpipolarNccOptions options;
      options.colour = colour;
      options.window = 9;
      const cv::Mat a = RandomTexture(64, 48, seed), b = RandomTexture(64, 48, seed + 10);
      const NccImage ia = NccImage::FromView(ViewOf(a), colour);
      const NccImage ib = NccImage::FromView(ViewOf(b), colour);
      std::vector<float> window;
      ASSERT_TRUE(ReferenceWindow(ia, 20, 20, options, &window));
      const cv::Mat templ = ia.pixels(cv::Rect(16, 16, 9, 9));
      cv::Mat expected;
      cv::matchTemplate(ib.pixels, templ, expected, cv::TM_CCOEFF_NORMED);
      for (int y = 10; y < 30 && !colour; y += 3) {
        for (int x = 10; x < 50; x += 5) {
          const float ncc = WindowNcc(ib, window.data(), x, y, options);
          EXPECT_NEAR(ncc, expected.at<float>(y - 4, x - 4), 2e-4) << x << "," << y;
        }
      }
      EXPECT_NEAR(WindowNcc(ia, window.data(), 20, 20, options), 1.0f, 1e-5);
      EXPECT_TRUE(std::isnan(WindowNcc(ib, window.data(), 2, 20, options)));  // off the image
    }
  }
}

// A shift of the image along x is found to sub-pixel accuracy by scanning a horizontal
// epipolar line whose "depth" is the pixel column.
TEST(EpipolarNccTest, ScanFindsSubPixelShifts) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 10; ++trial) {
    const double shift = std::uniform_real_distribution<double>(-4.0, 4.0)(rng);
    const cv::Mat a = RandomTexture(80, 40, static_cast<uint64_t>(trial + 1));
    cv::Mat b;
    const cv::Mat move = (cv::Mat_<double>(2, 3) << 1, 0, shift, 0, 1, 0);
    cv::warpAffine(a, b, move, a.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
    EpipolarNccOptions options;
    const NccImage ia = NccImage::FromView(ViewOf(a), false);
    const NccImage ib = NccImage::FromView(ViewOf(b), false);
    std::vector<float> window;
    ASSERT_TRUE(ReferenceWindow(ia, 40, 20, options, &window));
    EpipolarRay ray;  // pixel (d, 20)
    ray.a = Eigen::Vector3d(0, 20, 1);
    ray.b = Eigen::Vector3d(1, 0, 0);
    std::vector<float> scores;
    std::vector<EpipolarMatch> matches;
    EpipolarScanCounts counts;
    ScanEpipolarSegment(ib, window.data(), ray, 30.0, 50.0, options, &scores, &matches, &counts);
    EXPECT_EQ(counts.samples, 23u);
    ASSERT_FALSE(matches.empty());
    KeepBestMatches(1, 0, &matches);
    EXPECT_NEAR(matches[0].depth, 40.0 + shift, 0.12) << shift;
    EXPECT_GT(matches[0].ncc, 0.95f);
  }
}

TEST(EpipolarNccTest, RayProjectsAndTriangulates) {
  sim::CameraNetworkOptions network;
  network.cameras = 4;
  const std::vector<CameraModel> cameras = sim::MakeCameraNetwork(network);
  const CameraModel& ref = cameras[0];
  const Eigen::Vector3d direction =
      ref.R.transpose() * ref.K.inverse() * Eigen::Vector3d(300.5, 210.25, 1.0);
  const EpipolarRay ray = EpipolarRay::Of(cameras[1], ref.Center(), direction);
  for (double depth : {3.5, 4.5, 5.5}) {
    const Eigen::Vector3d point = ref.Center() + depth * direction;
    EXPECT_NEAR((ref.R * point + ref.t).z(), depth, 1e-9);
    ASSERT_TRUE(ray.InFront(depth));
    const Eigen::Vector2d pixel = ray.PixelAt(depth);
    EXPECT_LT((pixel - *cameras[1].Project(point)).norm(), 1e-9);
    EXPECT_NEAR(ray.DepthAt(pixel), depth, 1e-9);
  }
}

TEST(PhotoConsistencyTest, OptionsAreValidated) {
  EXPECT_EQ(PhotoConsistencyOptions{}.Validate(), "");
  PhotoConsistencyOptions options;
  options.matching.window = 8;
  EXPECT_NE(options.Validate().find("odd"), std::string::npos);
  options = {};
  options.pixel_step = 0;
  EXPECT_FALSE(options.Validate().empty());
  EXPECT_THROW(ComputePhotoConsistency({}, TriangleMesh{}, options), InputError);
  // Too few views is a failure reported as data.
  const PhotoConsistencyResult result = ComputePhotoConsistency({}, TriangleMesh{});
  EXPECT_FALSE(result.success);
  EXPECT_FALSE(result.reason.empty());
}

// The ring of 16 cameras at 640x480, made once.
const testing::SimulatedStills& Ring16() {
  static const testing::SimulatedStills ring = testing::MakeSimulatedStills(16, 640, 480, 1);
  return ring;
}

// Votes lie on the true surface; the most-voted cell along a viewing ray is at the truth;
// where the hull fills a concavity (its surface >= 4 cells from the truth on that ray), the
// ray's maximum is at the truth, not at the hull.
TEST(PhotoConsistencyTest, VotesLieOnTheTrueSurfaceOfSimulatedStills) {
  const testing::SimulatedStills& ring = Ring16();
  const PhotoConsistencyResult result = ComputePhotoConsistency(ring.views.views, ring.hull);
  ASSERT_TRUE(result.success) << result.reason;
  EXPECT_TRUE(result.warnings.empty());
  const PhotoConsistencyStats& stats = result.stats;
  std::printf("[ photo-consistency ] %s\n", stats.BriefReport().c_str());
  EXPECT_NEAR(stats.footprint, ring.footprint, 0.1 * ring.footprint);
  EXPECT_GT(stats.votes_in_hull, stats.reference_pixels / 2);
  EXPECT_LT(stats.votes_outside_hull, stats.votes_in_hull / 20);

  const double cell = result.volume.cell_size;
  const NearestPoint truth(ring.truth);
  const std::vector<double> share =
      testing::VoteShareWithin(result.volume, truth, {cell, 2 * cell, 3 * cell});
  std::printf(
      "[ photo-consistency ] votes within 1/2/3 cells (%.1f mm) of the truth: %.3f %.3f %.3f\n",
      cell * 1e3, share[0], share[1], share[2]);
  EXPECT_GE(share[1], 0.83);
  EXPECT_GE(share[2], 0.87);

  VoxelGrid geometry;
  geometry.origin = result.volume.origin;
  geometry.voxel_size = cell;
  geometry.dims = result.volume.dims;
  const std::vector<uint8_t> solid = RasterizeMesh(ring.hull, geometry).occupied;
  std::vector<Eigen::Vector3d> maxima, entries;
  for (size_t v = 0; v < ring.views.views.size(); v += 3) {
    for (const testing::RayMaximum& m :
         testing::RayMaxima(result.volume, solid, ring.views.views[v], 2, 3.0f)) {
      if (!m.has_solid_entry) continue;
      maxima.push_back(m.cell_centre);
      entries.push_back(m.solid_entry);
    }
  }
  const std::vector<double> max_distance = truth.Distances(maxima);
  const std::vector<double> entry_distance = truth.Distances(entries);
  size_t near = 0, concave = 0, concave_at_truth = 0, concave_at_hull = 0;
  for (size_t r = 0; r < maxima.size(); ++r) {
    if (max_distance[r] <= 2 * cell) ++near;
    if (entry_distance[r] < 4 * cell) continue;
    ++concave;
    if (max_distance[r] <= 2 * cell) ++concave_at_truth;
    if ((maxima[r] - entries[r]).norm() <= 2 * cell) ++concave_at_hull;
  }
  ASSERT_GT(maxima.size(), 5000u);
  ASSERT_GT(concave, 100u);
  const double near_share = static_cast<double>(near) / static_cast<double>(maxima.size());
  const double truth_share = static_cast<double>(concave_at_truth) / static_cast<double>(concave);
  const double hull_share = static_cast<double>(concave_at_hull) / static_cast<double>(concave);
  std::printf(
      "[ photo-consistency ] ray maxima (>= 3 votes) within 2 cells: %.3f of %zu; "
      "concave rays %zu: at the truth %.3f, at the hull %.3f\n",
      near_share, maxima.size(), concave, truth_share, hull_share);
  EXPECT_GE(near_share, 0.95);
  EXPECT_GE(truth_share, 0.90);
  EXPECT_LE(hull_share, 0.03);
}

// The votes do not depend on the number of threads or the order of the work items.
TEST(PhotoConsistencyTest, VotesAreDeterministic) {
  const testing::SimulatedStills& ring = Ring16();
  PhotoConsistencyOptions options;
  options.pixel_step = 4;
  options.weight_by_ncc = true;
  options.threads = 1;
  const PhotoConsistencyResult one = ComputePhotoConsistency(ring.views.views, ring.hull, options);
  options.threads = 2;
  options.rows_per_item = 3;
  const PhotoConsistencyResult two = ComputePhotoConsistency(ring.views.views, ring.hull, options);
  ASSERT_TRUE(one.success && two.success);
  EXPECT_EQ(one.stats.matches, two.stats.matches);
  EXPECT_GT(one.stats.votes_in_hull, 0u);
  EXPECT_TRUE(one.volume.votes == two.volume.votes);
}

TEST(PhotoConsistencyTest, CancellationIsAFailureWithAReason) {
  const testing::SimulatedStills& ring = Ring16();
  Progress progress("test", 0);
  progress.Cancel();
  const PhotoConsistencyResult result =
      ComputePhotoConsistency(ring.views.views, ring.hull, {}, &progress);
  EXPECT_FALSE(result.success);
  EXPECT_EQ(result.reason, "cancelled");
}

}  // namespace
}  // namespace silnet::aggregator
