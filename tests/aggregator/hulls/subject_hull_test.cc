// Hulls of the simulated walking subject seen by a simulated ring of cameras, against the
// simulator's ground truth: its exact masks and the subject's surface.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <vector>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/silhouette_interpolation.h"
#include "aggregator/hulls/voxel_hull.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"
#include "sim/scene/scene.h"
#include "tests/aggregator/hulls/hull_comparison.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

constexpr double kVoxel = 0.01;  // metres

// A ring of cameras and one walking person, with a renderer per camera.
struct Capture {
  std::vector<CameraModel> cameras;
  std::unique_ptr<sim::Scene> scene;
  std::vector<std::unique_ptr<sim::CameraRenderer>> renderers;

  // Exact masks of every camera at reference time `time` (seconds).
  std::vector<cv::Mat> MasksAt(double time) const {
    std::vector<cv::Mat> masks(cameras.size());
    for (size_t c = 0; c < cameras.size(); ++c)
      renderers[c]->Render(time, 0, &masks[c], nullptr);
    return masks;
  }
  // Camera c's mask of its own (integer) frame.
  cv::Mat FrameMask(size_t c, int frame) const {
    cv::Mat mask;
    renderers[c]->Render(cameras[c].ExposureTime(frame), 0, &mask, nullptr);
    return mask;
  }
};

Capture MakeCapture(const sim::CameraNetworkOptions& network, double speed) {
  Capture capture;
  capture.cameras = sim::MakeCameraNetwork(network);
  sim::SceneOptions scene;
  scene.seed = 5;
  scene.mean_speed = speed;
  scene.time_begin = -1.0;
  scene.time_end = 20.0;
  capture.scene = std::make_unique<sim::Scene>(scene);
  for (size_t c = 0; c < capture.cameras.size(); ++c) {
    capture.renderers.push_back(std::make_unique<sim::CameraRenderer>(
        capture.cameras[c], *capture.scene, sim::RenderSettings{}, static_cast<int>(c)));
  }
  return capture;
}

// True if the voxel holding `p`, or one of its 26 neighbours, is occupied: `p` lies in the
// hull up to one voxel.
bool WithinOneVoxel(const VoxelGrid& grid, const Eigen::Vector3d& p) {
  const Eigen::Vector3d g = (p - grid.origin) / grid.voxel_size;
  const int i = static_cast<int>(std::floor(g.x())), j = static_cast<int>(std::floor(g.y()));
  const int k = static_cast<int>(std::floor(g.z()));
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (grid.IsOccupied(i + dx, j + dy, k + dz)) return true;
      }
    }
  }
  return false;
}

// All views' missed and spurious pixels over all views' silhouette pixels.
struct TotalReprojection {
  double missed = 0, spurious = 0, worst_missed = 0;
};

TotalReprojection Total(const std::vector<ViewReprojection>& views) {
  double silhouette = 0, missed = 0, spurious = 0;
  TotalReprojection total;
  for (const ViewReprojection& v : views) {
    silhouette += static_cast<double>(v.silhouette_pixels);
    missed += static_cast<double>(v.missed_pixels);
    spurious += static_cast<double>(v.spurious_pixels);
    total.worst_missed = std::max(total.worst_missed, v.missed_fraction);
  }
  total.missed = missed / silhouette;
  total.spurious = spurious / silhouette;
  return total;
}

// The synchronised ring (seed 3) watching the subject walk at 0.9 m/s.
Capture SynchronisedRing() {
  sim::CameraNetworkOptions network;
  network.seed = 3;
  network.max_offset = 0.0;
  return MakeCapture(network, 0.9);
}

TEST(SubjectHullTest, SynchronisedCaptureReprojectsOntoTheSilhouettes) {
  const Capture capture = SynchronisedRing();
  silnet::testing::TempDir dir;
  for (double time : {1.0, 4.3}) {
    const std::vector<cv::Mat> masks = capture.MasksAt(time);
    VoxelHullOptions options;
    options.voxel_size = kVoxel;
    const VoxelHullResult hull = CarveVoxelHull(capture.cameras, masks, options);
    ASSERT_TRUE(hull.success) << hull.reason;
    const TriangleMesh mesh = ExtractBoundaryMesh(hull.grid);
    const MeshCheck check = CheckClosedManifold(mesh);
    EXPECT_TRUE(check.closed_manifold) << check.reason;

    const std::vector<ViewReprojection> views =
        MeasureHullReprojection(mesh, capture.cameras, masks);
    for (const ViewReprojection& view : views)
      EXPECT_LE(view.missed_fraction, 0.01) << view.camera_id << " at " << time << " s";
    const TotalReprojection total = Total(views);
    std::printf(
        "t = %.1f s: %zu voxels, %zu triangles, missed %.4f%% (worst view %.4f%%), "
        "spurious %.2f%%\n",
        time, hull.grid.CountOccupied(), mesh.triangles.size(), 100 * total.missed,
        100 * total.worst_missed, 100 * total.spurious);

    // Every surface point of the subject lies in the hull, up to one voxel.
    std::mt19937_64 rng(11);
    size_t samples = 0, outside = 0;
    for (const sim::Primitive& primitive : capture.scene->PrimitivesAt(time)) {
      for (const Eigen::Vector3d& p : primitive.SampleSurface(200, rng)) {
        ++samples;
        if (!WithinOneVoxel(hull.grid, p)) ++outside;
      }
    }
    EXPECT_GT(samples, 1000u);
    EXPECT_EQ(outside, 0u) << "of " << samples << " surface samples at " << time << " s";

    // The overlay shows exactly the missed pixels in red; the PLY round-trips.
    const cv::Mat rendered = RenderMeshSilhouette(mesh, capture.cameras[0]);
    const std::string overlay_path = (dir / "overlay.png").string();
    WriteReprojectionOverlay(overlay_path, rendered, masks[0]);
    const cv::Mat overlay = cv::imread(overlay_path, cv::IMREAD_COLOR);
    ASSERT_FALSE(overlay.empty());
    cv::Mat red, blue;
    cv::inRange(overlay, cv::Scalar(0, 0, 255), cv::Scalar(0, 0, 255), red);
    cv::inRange(overlay, cv::Scalar(255, 0, 0), cv::Scalar(255, 0, 0), blue);
    EXPECT_EQ(static_cast<size_t>(cv::countNonZero(red)), views[0].missed_pixels);
    EXPECT_EQ(static_cast<size_t>(cv::countNonZero(blue)), views[0].spurious_pixels);
    const std::string ply_path = (dir / "hull.ply").string();
    WritePlyMesh(ply_path, mesh);
    const TriangleMesh back = ReadPlyMesh(ply_path);
    EXPECT_EQ(back.triangles, mesh.triangles);
    EXPECT_TRUE(back.vertices == mesh.vertices);
  }
}

// The subject's true surface: samples of each body part not inside another part.
std::vector<Eigen::Vector3d> TrueSurface(const std::vector<sim::Primitive>& parts, int per_part) {
  std::mt19937_64 rng(17);
  std::vector<Eigen::Vector3d> surface;
  for (size_t p = 0; p < parts.size(); ++p) {
    for (const Eigen::Vector3d& x : parts[p].SampleSurface(per_part, rng)) {
      bool covered = false;
      for (size_t q = 0; q < parts.size() && !covered; ++q)
        covered = q != p && parts[q].Contains(x);
      if (!covered) surface.push_back(x);
    }
  }
  return surface;
}

TEST(SubjectHullTest, PolyhedralHullContainsTheSubjectAndMatchesTheVoxelHull) {
  const Capture capture = SynchronisedRing();
  for (double time : {1.0, 2.0, 3.0, 4.3}) {
    const std::vector<cv::Mat> masks = capture.MasksAt(time);
    const PolyhedralHullResult hull = ComputePolyhedralHull(capture.cameras, masks);
    ASSERT_TRUE(hull.success) << hull.reason << " at " << time << " s";
    const MeshCheck check = CheckClosedManifold(hull.mesh);
    EXPECT_TRUE(check.closed_manifold) << check.reason;

    const std::vector<ViewReprojection> views =
        MeasureHullReprojection(hull.mesh, capture.cameras, masks);
    for (const ViewReprojection& view : views)
      EXPECT_LE(view.missed_fraction, 0.01) << view.camera_id << " at " << time << " s";

    // Every true surface point lies inside the hull, up to one voxel (rasterised).
    VoxelHullOptions options;
    options.voxel_size = kVoxel;
    const VoxelHullResult carved = CarveVoxelHull(capture.cameras, masks, options);
    ASSERT_TRUE(carved.success) << carved.reason;
    const VoxelGrid raster = RasterizeMesh(hull.mesh, carved.grid);
    const std::vector<Eigen::Vector3d> truth = TrueSurface(capture.scene->PrimitivesAt(time), 400);
    size_t outside = 0;
    for (const Eigen::Vector3d& p : truth) {
      if (!WithinOneVoxel(raster, p)) ++outside;
    }
    EXPECT_GT(truth.size(), 2000u);
    EXPECT_EQ(outside, 0u) << "of " << truth.size() << " surface samples at " << time << " s";

    // Polyhedral and volumetric hulls differ only within one voxel of the polyhedral surface.
    const hull_testing::HullDifference difference =
        hull_testing::CompareWithCarvedHull(hull.mesh, raster, carved.grid);
    // A handful of voxels (1 to 7 in ~2400 differing at 1 cm, about one pixel here) differ
    // by a little more than a voxel diagonal; not yet explained (see docs/PERFORMANCE.md).
    EXPECT_LE(difference.far, difference.differing / 200)
        << "of " << difference.differing << " differing voxels at " << time << " s";
    const size_t differ = difference.differing;

    // Distance to the true surface (sampled Hausdorff), reported.
    std::mt19937_64 rng(5);
    const SurfaceDistances distances =
        MeasureSurfaceDistances(SampleMeshSurface(hull.mesh, 20000, rng), truth);
    EXPECT_LT(distances.a_to_b_mean, 0.05);
    const TotalReprojection total = Total(views);
    std::printf(
        "t = %.1f s: polyhedral hull %zu triangles, %zu triple points; missed %.4f%%, "
        "spurious %.2f%%; %zu of %zu voxels differ from the carved hull; hull to surface: "
        "mean %.1f mm, max (Hausdorff) %.1f mm; surface to hull: mean %.1f mm, max %.1f mm\n",
        time, hull.mesh.triangles.size(), hull.stats.triple_points, 100 * total.missed,
        100 * total.spurious, differ, carved.grid.CountOccupied(), 1000 * distances.a_to_b_mean,
        1000 * distances.a_to_b_max, 1000 * distances.b_to_a_mean, 1000 * distances.b_to_a_max);
    RecordProperty("hausdorff_mm_t" + std::to_string(static_cast<int>(10 * time)),
                   std::to_string(1000 * distances.Hausdorff()));
  }
}

// Reprojection errors, against the true silhouettes at the common time, of hulls carved
// from each camera's nearest frame and from its interpolated silhouette.
struct SubFrameComparison {
  double nearest = 0;                    // missed + spurious fraction, summed over the times
  double interpolated = 0;               // the same with interpolated silhouettes
  double nearest_missed = 0;             // missed fraction alone, summed over the times
  double interpolated_missed = 0;        // the same with interpolated silhouettes
  double worst_interpolated_missed = 0;  // largest missed fraction at one time
};

// Unsynchronised cameras at `fps` watching a person walking at `speed` m/s: offsets whose
// fractional parts put every camera 0.3 to 0.5 of a frame from its nearest frame at the
// chosen times (multiples of 1 / fps).
SubFrameComparison CompareNearestAndInterpolated(double fps, double speed) {
  sim::CameraNetworkOptions network;
  network.seed = 4;
  network.fps = fps;
  network.max_offset = 0.0;
  const std::vector<double> offsets = {0.35, -2.6, 4.45, 1.3, -0.4, 3.62, -5.5, 2.38};
  Capture capture = MakeCapture(network, speed);
  capture.renderers.clear();  // renderers copy their camera: rebuild them with the offsets
  for (size_t i = 0; i < capture.cameras.size(); ++i) {
    capture.cameras[i].time_offset = offsets[i];
    capture.renderers.push_back(std::make_unique<sim::CameraRenderer>(
        capture.cameras[i], *capture.scene, sim::RenderSettings{}, static_cast<int>(i)));
  }
  SubFrameComparison sums;
  for (double time : {2.0, 3.0, 5.6}) {
    std::vector<cv::Mat> nearest, interpolated;
    for (size_t c = 0; c < capture.cameras.size(); ++c) {
      const double frame = capture.cameras[c].FrameAt(time);
      const int k = static_cast<int>(std::floor(frame));
      const double f = frame - k;
      EXPECT_GT(std::min(f, 1 - f), 0.25) << "camera " << c;
      const cv::Mat mask_k = capture.FrameMask(c, k), mask_k1 = capture.FrameMask(c, k + 1);
      nearest.push_back(f < 0.5 ? mask_k : mask_k1);
      interpolated.push_back(InterpolateSilhouette(mask_k, mask_k1, f));
    }
    const std::vector<cv::Mat> truth = capture.MasksAt(time);
    VoxelHullOptions options;
    options.voxel_size = kVoxel;
    const VoxelHullResult from_nearest = CarveVoxelHull(capture.cameras, nearest, options);
    const VoxelHullResult from_interpolated =
        CarveVoxelHull(capture.cameras, interpolated, options);
    EXPECT_TRUE(from_nearest.success && from_interpolated.success);
    const TotalReprojection near = Total(
        MeasureHullReprojection(ExtractBoundaryMesh(from_nearest.grid), capture.cameras, truth));
    const TotalReprojection interp = Total(MeasureHullReprojection(
        ExtractBoundaryMesh(from_interpolated.grid), capture.cameras, truth));
    std::printf(
        "%.0f fps, %.1f m/s, t = %.2f s, against the true silhouettes: nearest frame "
        "missed %.2f%% spurious %.2f%%; interpolated missed %.2f%% spurious %.2f%%\n",
        fps, speed, time, 100 * near.missed, 100 * near.spurious, 100 * interp.missed,
        100 * interp.spurious);
    EXPECT_LT(interp.missed + interp.spurious, near.missed + near.spurious) << time << " s";
    EXPECT_LT(interp.missed, near.missed) << time << " s";
    sums.nearest += near.missed + near.spurious;
    sums.interpolated += interp.missed + interp.spurious;
    sums.nearest_missed += near.missed;
    sums.interpolated_missed += interp.missed;
    sums.worst_interpolated_missed = std::max(sums.worst_interpolated_missed, interp.missed);
  }
  return sums;
}

TEST(SubjectHullTest, SubFrameInterpolationBeatsTheNearestFrameAt15Fps) {
  const SubFrameComparison sums = CompareNearestAndInterpolated(15.0, 1.4);
  EXPECT_LT(sums.interpolated, 0.75 * sums.nearest);
}

TEST(SubjectHullTest, SubFrameInterpolationBeatsTheNearestFrameAt30Fps) {
  // At the nominal rate and pace the interpolated hull meets the design target (at most 1 %
  // of silhouette pixels missed) where the nearest frame does not.
  const SubFrameComparison sums = CompareNearestAndInterpolated(30.0, 0.9);
  EXPECT_LE(sums.worst_interpolated_missed, 0.01);
  EXPECT_LT(sums.interpolated_missed, 0.3 * sums.nearest_missed);
  EXPECT_LT(sums.interpolated, sums.nearest);
}

}  // namespace
}  // namespace silnet::aggregator
