// Visual hulls of real captures (the shared data folder, see its README.md) and the `hulls`
// sequence job on a small simulated dataset with sub-frame time offsets.

#include "tests/support/real_data.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <utility>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/hull_sequence_job.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/real_datasets.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/voxel_hull.h"
#include "aggregator/live/recent_contours.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/io/frame_record.h"
#include "shared/io/session_log.h"
#include "shared/record/record_log.h"
#include "shared/silhouette/contour_codec.h"
#include "shared/silhouette/silhouette_contour.h"
#include "shared/util/check.h"
#include "sim/dataset_generator.h"
#include "tests/aggregator/hulls/hull_comparison.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

const std::filesystem::path kData = SILNET_SHARED_DATA_DIR;
// Measured thresholds (voxels of 1/200 of the bounds diagonal). The hull misses 0.4-2 % of
// silhouette pixels in a typical view, nearly all within 2 px of its outline (calibration and
// segmentation disagree by a pixel or two, measured: <= 0.42 % of pixels beyond 2 px in every
// view but one, independent of the voxel size). Dancer view 4 carries a thin wire-like
// streak above the head that no other view confirms: 6.6 % missed, 4.3 % beyond 2 px.
constexpr double kMissed = 0.035;  // per view, raw (measured worst 3.41 %)
// Per view, > 2 px from the hull: measured worst 0.42 % carved, 0.72 % exact (wd2_18).
constexpr double kMissedBeyond2Px = 0.01;
constexpr double kDancer4Missed = 0.07;     // dancer0004, raw (measured 6.59 %)
constexpr double kDancer4Beyond2Px = 0.05;  // dancer0004, > 2 px (measured 4.27 %, exact 4.45 %)

// A hull of one capture and how it reprojects.
struct RealHull {
  TriangleMesh mesh;
  MeshCheck check;
  std::vector<ViewReprojection> views;
  std::vector<double> missed_beyond_2px;  // per view: missed fraction > 2 px from the hull
};

// Checks the hull's mesh and reprojects it into every view of the capture; prints the figures.
void Measure(const RealCapture& capture, RealHull& result) {
  result.check = CheckClosedManifold(result.mesh);
  for (size_t c = 0; c < capture.cameras.size(); ++c) {
    const cv::Mat rendered = RenderMeshSilhouette(result.mesh, capture.cameras[c]);
    result.views.push_back(CompareWithSilhouette(rendered, capture.masks[c]));
    result.views.back().camera_id = capture.cameras[c].id;
    cv::Mat widened;
    cv::dilate(rendered, widened, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
    result.missed_beyond_2px.push_back(
        CompareWithSilhouette(widened, capture.masks[c]).missed_fraction);
  }
  for (size_t c = 0; c < result.views.size(); ++c) {
    const ViewReprojection& v = result.views[c];
    std::printf("  %-10s %7zu px  missed %.3f %% (beyond 2 px %.3f %%)  extra %.3f %%\n",
                v.camera_id.c_str(), v.silhouette_pixels, 100 * v.missed_fraction,
                100 * result.missed_beyond_2px[c], 100 * v.spurious_fraction);
  }
}

// Expects the hull closed and every view's silhouette covered but `missed` of its pixels
// (`streak_missed` in dancer0004), and all but kMissedBeyond2Px beyond 2 px of the hull.
void ExpectClosedAndCovering(const RealHull& hull, double missed, double streak_missed) {
  EXPECT_TRUE(hull.check.closed_manifold) << hull.check.reason;
  for (size_t c = 0; c < hull.views.size(); ++c) {
    const bool streak = hull.views[c].camera_id == "dancer0004";
    EXPECT_LE(hull.views[c].missed_fraction, streak ? streak_missed : missed)
        << hull.views[c].camera_id;
    EXPECT_LE(hull.missed_beyond_2px[c], streak ? kDancer4Beyond2Px : kMissedBeyond2Px)
        << hull.views[c].camera_id;
  }
}

// Carves, meshes and reprojects one capture.
RealHull CarveAndMeasure(const RealCapture& capture, const std::string& name) {
  const ViewingConeBounds bounds = ComputeViewingConeBounds(capture.cameras, capture.masks);
  EXPECT_TRUE(bounds.success) << bounds.reason;
  VoxelHullOptions options;
  options.voxel_size = bounds.box.diagonal().norm() / 200;
  const VoxelHullResult hull = CarveVoxelHull(capture.cameras, capture.masks, options);
  EXPECT_TRUE(hull.success) << hull.reason;
  RealHull result;
  result.mesh = ExtractBoundaryMesh(hull.grid);
  std::printf("%s: voxel %.4f, %zu voxels, %zu vertices, %zu triangles\n", name.c_str(),
              options.voxel_size, hull.grid.CountOccupied(), result.mesh.vertices.size(),
              result.mesh.triangles.size());
  Measure(capture, result);
  return result;
}

// A 10x2 raster: row 0 bits 1 at x = 0 and 9, row 1 all 0; each row padded to two bytes.
TEST(RealDataHullTest, ReadPbmReadsBitsAndRefusesBadHeaders) {
  silnet::testing::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  const cv::Mat mask =
      ReadPbm(write("ok.pbm", "P4\n# comment\n10 2\n" + std::string("\x80\x40\0\0", 4)), 1);
  ASSERT_EQ(mask.size(), cv::Size(10, 2));
  EXPECT_EQ(cv::countNonZero(mask), 2);
  EXPECT_EQ(mask.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(mask.at<uint8_t>(0, 9), 255);
  EXPECT_EQ(cv::countNonZero(ReadPbm(dir / "ok.pbm", 0)), 18);
  const auto refused = [&](const std::filesystem::path& path, const std::string& fragment) {
    EXPECT_THAT([&] { ReadPbm(path, 1); },
                ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(fragment)));
  };
  refused(write("wide.pbm", "P4\n2147483647 1\n"), "bad PBM size 2147483647x1");
  refused(write("huge.pbm", "P4\n60000 60000\n"), "truncated at row 0");
  refused(write("cut.pbm", "P4\n10 2\n" + std::string("\x80\x40\0", 3)), "truncated at row 1");
  refused(write("ascii.pbm", "P1\n1 1\n1\n"), "not a binary PBM");
}

// One Utrecht-style camera folder: config.xml beside a one-frame 32x24 video.
TEST(RealDataHullTest, UtrechtCamerasAreReadAndNonFiniteOrMalformedValuesRefused) {
  silnet::testing::TempDir dir;
  const std::filesystem::path camera = dir / "cam1";
  std::filesystem::create_directories(camera);
  cv::VideoWriter video((camera / "video.avi").string(),
                        cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, cv::Size(32, 24));
  ASSERT_TRUE(video.isOpened());
  video.write(cv::Mat(24, 32, CV_8UC3, cv::Scalar(90, 90, 90)));
  video.release();
  const auto write = [&](cv::Matx33d k, cv::Vec3d t) {
    cv::FileStorage fs((camera / "config.xml").string(), cv::FileStorage::WRITE);
    fs << "CameraMatrix" << cv::Mat(k) << "DistortionCoeffs" << cv::Mat(cv::Vec<double, 5>::all(0))
       << "Rotation" << cv::Mat(cv::Vec3d(0.0, 0.1, 0.0)) << "Translation" << cv::Mat(t);
  };
  const cv::Matx33d k(40, 0, 16, 0, 40, 12, 0, 0, 1);
  write(k, {1, 2, 3000});
  const std::vector<CameraModel> cameras = LoadUtrechtCameras(dir.path(), 25.0);
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].id, "cam1");
  EXPECT_EQ(cameras[0].width, 32);
  EXPECT_EQ(cameras[0].height, 24);
  EXPECT_DOUBLE_EQ(cameras[0].K(0, 2), 16.0);
  EXPECT_DOUBLE_EQ(cameras[0].t.z(), 3000.0);
  EXPECT_NEAR(cameras[0].R(0, 2), std::sin(0.1), 1e-12);
  const auto refused = [&](const std::string& fragment) {
    EXPECT_THAT([&] { LoadUtrechtCameras(dir.path(), 25.0); },
                ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(fragment)));
  };
  write(k, {1, std::nan(""), 3000});
  refused("Translation holds a value that is not finite");
  write(k, {1, 2, INFINITY});
  refused("Translation holds a value that is not finite");
  write(cv::Matx33d(40, 0, 16, 0, 40, 12, 0, 1, 1), {1, 2, 3000});
  refused("not upper triangular");
  write(cv::Matx33d(-40, 0, 16, 0, 40, 12, 0, 0, 1), {1, 2, 3000});
  refused("no focal length");
}

TEST(RealDataHullTest, InriaDancer) {
  const std::filesystem::path folder = kData / "inria-dancer-silhouettes";
  SILNET_REQUIRE_REAL_DATA(folder);
  RealCapture capture = LoadInriaDancer(folder);
  ASSERT_EQ(capture.cameras.size(), 8u);
  // Views 2, 3, 4 and 6 hold stray foreground blobs away from the dancer that no other view
  // confirms; the hull is checked against the dancer, the largest blob of each view.
  for (cv::Mat& mask : capture.masks)
    mask = KeepLargestComponent(mask);
  ExpectClosedAndCovering(CarveAndMeasure(capture, "dancer"), kMissed, kDancer4Missed);
}

TEST(RealDataHullTest, TsinghuaWd2) {
  const std::filesystem::path folder = kData / "tsinghua-wd2-20cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  const RealCapture capture = LoadTsinghuaWd2(folder, false);
  ASSERT_EQ(capture.cameras.size(), 20u);
  // Measured worst raw miss 2.03 % (wd2_01); the file's radial coefficients change it by
  // <= 0.4 points per view, so they are left out as the dataset's own code does.
  ExpectClosedAndCovering(CarveAndMeasure(capture, "wd2"), kMissed, kMissed);
}

// Measured misses of the polyhedral hulls (default contours): dancer worst 4.09 %
// (dancer0005), dancer0004 7.92 % (the streak above); WD2 worst 3.87 % (wd2_01). Fewer pixels
// than the carved hull's, since its faces do not overshoot.
constexpr double kPolyhedralMissed = 0.05;
constexpr double kPolyhedralDancer4Missed = 0.085;

// The polyhedral hull of a real capture: closed, and reprojecting onto the silhouettes.
void CheckPolyhedral(const RealCapture& capture, const std::string& name) {
  const PolyhedralHullResult exact = ComputePolyhedralHull(capture.cameras, capture.masks);
  ASSERT_TRUE(exact.success) << name << ": " << exact.reason;
  EXPECT_FALSE(exact.stats.faces_with_cuts) << name << ": faces not triangulated as polygons";
  // Gaps between faces that decided a near-degenerate configuration differently are slivers
  // (measured on WD2 with its rotations as printed, to six decimals: 4, the widest 0.16 mm
  // across; none with the nearest rotations); a wide one is a face lost, not a sliver.
  EXPECT_LT(exact.stats.widest_gap, 1e-3) << name;
  std::printf(
      "%s polyhedral: %zu triangles, %zu triple points, %zu gaps filled (%.2f mm^2, widest "
      "%.3f mm)\n",
      name.c_str(), exact.mesh.triangles.size(), exact.stats.triple_points, exact.stats.gaps_filled,
      1e6 * exact.stats.gap_area, 1000 * exact.stats.widest_gap);
  RealHull hull;
  hull.mesh = exact.mesh;
  Measure(capture, hull);
  ExpectClosedAndCovering(hull, kPolyhedralMissed, kPolyhedralDancer4Missed);
}

TEST(RealDataHullTest, PolyhedralHullOfTheDancer) {
  const std::filesystem::path folder = kData / "inria-dancer-silhouettes";
  SILNET_REQUIRE_REAL_DATA(folder);
  RealCapture capture = LoadInriaDancer(folder);
  for (cv::Mat& mask : capture.masks)
    mask = KeepLargestComponent(mask);
  CheckPolyhedral(capture, "dancer");
}

TEST(RealDataHullTest, PolyhedralHullOfWd2) {
  const std::filesystem::path folder = kData / "tsinghua-wd2-20cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  CheckPolyhedral(LoadTsinghuaWd2(folder, false), "wd2");
}

// Each face's chart is narrowed in an order learnt from the faces its thread computed before;
// the final chart box depends on the bounds alone, so the mesh is the same for any thread count
// on a real capture too (WD2).
TEST(RealDataHullTest, ThreadsGiveTheSameMeshOnWd2) {
  const std::filesystem::path folder = kData / "tsinghua-wd2-20cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  const RealCapture capture = LoadTsinghuaWd2(folder, false);
  hull_testing::ExpectSameHullOnThreads(capture.cameras, capture.masks, 2);
}

// A gap wider than the options allow is a face lost, not a sliver: the hull is refused and
// says so, rather than written with the hole filled. WD2's file prints its rotations to six
// decimals; taken as printed (not quite rotations: the loader uses the nearest ones, which
// close without a gap) its faces leave slivers, the widest 2.3e-6 of the hull's size across
// (the default allows 1e-3); allowed 1e-6, the hull is refused with the widest one's width.
// The gaps are the face-by-face sweeps': the edges traced once from the viewing edges close
// the same hull without any.
TEST(RealDataHullTest, GapsWiderThanAllowedAreRefused) {
  const std::filesystem::path folder = kData / "tsinghua-wd2-20cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  RealCapture capture = LoadTsinghuaWd2(folder, false);
  for (CameraModel& camera : capture.cameras)
    camera.R = (camera.R.array() * 1e6).round().matrix() / 1e6;
  const PolyhedralHullResult traced = ComputePolyhedralHull(capture.cameras, capture.masks);
  ASSERT_TRUE(traced.success) << traced.reason;
  EXPECT_TRUE(traced.stats.traced_edges);
  EXPECT_EQ(traced.stats.gaps_filled, 0u);
  PolyhedralHullOptions options;
  options.trace_edges = false;
  const PolyhedralHullResult filled =
      ComputePolyhedralHull(capture.cameras, capture.masks, options);
  ASSERT_TRUE(filled.success) << filled.reason;
  EXPECT_GT(filled.stats.gaps_filled, 0u) << "the printed rotations no longer leave slivers";
  // The same solid but for the filled slivers (1e-6 of the volume).
  EXPECT_NEAR(MeshVolume(traced.mesh), MeshVolume(filled.mesh), 1e-5 * MeshVolume(filled.mesh));
  options.widest_gap_fraction = 1e-6;
  const PolyhedralHullResult refused =
      ComputePolyhedralHull(capture.cameras, capture.masks, options);
  EXPECT_FALSE(refused.success);
  EXPECT_NE(refused.reason.find("leave a gap"), std::string::npos) << refused.reason;
  std::printf("wd2 with gaps up to 1e-6 of its size filled: %s\n", refused.reason.c_str());
}

// EPVH's own alien set (issue 20): the exact hull of cameras 0..k-1 is closed and manifold
// for every k measured against EPVH, and of all 24, and adds at most 0.3 % to any silhouette
// (measured <= 0.21 %). The set's cameras and contours disagree more the more views join
// (measured missed beyond 2 px: <= 0.36 % per view with 4 views, <= 1.5 % with 8, 2.3-7.6 % with
// 24 and 26 % in view 16), so its coverage is asserted with the 4 views only.
TEST(RealDataHullTest, PolyhedralHullOfEpvhAlienClosesForEveryViewCount) {
  const std::filesystem::path folder = kData / "epvh-alien-24cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  const RealCapture all = LoadEpvhAlien(folder);
  ASSERT_EQ(all.cameras.size(), 24u);
  EXPECT_THROW(LoadEpvhAlien(folder, 25), InputError);
  for (const long views : {4L, 8L, 16L, 24L}) {
    RealCapture capture;
    capture.cameras.assign(all.cameras.begin(), all.cameras.begin() + views);
    capture.masks.assign(all.masks.begin(), all.masks.begin() + views);
    const PolyhedralHullResult exact = ComputePolyhedralHull(capture.cameras, capture.masks);
    ASSERT_TRUE(exact.success) << views << " views: " << exact.reason;
    EXPECT_FALSE(exact.stats.faces_with_cuts) << views << " views";
    EXPECT_EQ(exact.stats.gaps_filled, 0u) << views << " views";
    if (views == 4) {
      // The same solid as the assembly with the sweeps' cuts, in a sixth of the triangles
      // (measured 14812 against 93390).
      PolyhedralHullOptions with_cuts;
      with_cuts.faces_as_polygons = false;
      const PolyhedralHullResult cut =
          ComputePolyhedralHull(capture.cameras, capture.masks, with_cuts);
      ASSERT_TRUE(cut.success) << cut.reason;
      EXPECT_TRUE(cut.stats.faces_with_cuts);
      EXPECT_NEAR(MeshVolume(exact.mesh), MeshVolume(cut.mesh), 1e-6 * MeshVolume(cut.mesh));
      EXPECT_LT(5 * exact.mesh.triangles.size(), cut.mesh.triangles.size());
    }
    std::printf("alien, %ld views: %zu triangles, %zu gaps filled\n", views,
                exact.mesh.triangles.size(), exact.stats.gaps_filled);
    RealHull hull;
    hull.mesh = exact.mesh;
    Measure(capture, hull);
    EXPECT_TRUE(hull.check.closed_manifold) << views << " views: " << hull.check.reason;
    for (size_t c = 0; c < hull.views.size(); ++c) {
      EXPECT_LE(hull.views[c].spurious_fraction, 0.003) << hull.views[c].camera_id;
      if (views == 4) {
        EXPECT_LE(hull.missed_beyond_2px[c], 0.005) << hull.views[c].camera_id;
      }
    }
  }
}

// Polyhedral hulls from covering contours (PolyhedralHullOptions::contour_cover_pixel_centres)
// with the captures' own cameras, which disagree with the masks by 1-2 px: per view, at most
// kCoveringMissedFar of the silhouette pixels missed farther than 2 px from its outline (issue
// 16, item 5), but in the views named in `exceptions`, up to the fraction given there.
constexpr double kCoveringMissedFar = 0.005;

void CheckCoveringHull(const RealCapture& capture, const std::string& name, bool expect_closed,
                       const std::map<std::string, double>& exceptions) {
  PolyhedralHullOptions options;
  options.contour_cover_pixel_centres = true;
  const PolyhedralHullResult exact = ComputePolyhedralHull(capture.cameras, capture.masks, options);
  std::printf("%s covering: %s, %zu triangles, %zu cone faces, %zu gaps filled\n", name.c_str(),
              exact.success ? "closed" : exact.reason.c_str(), exact.mesh.triangles.size(),
              exact.stats.cone_faces, exact.stats.gaps_filled);
  if (expect_closed) {
    EXPECT_TRUE(exact.success) << name << ": " << exact.reason;
  }
  ASSERT_FALSE(exact.mesh.triangles.empty()) << name << ": " << exact.reason;
  const std::vector<ViewReprojection> views =
      MeasureHullReprojection(exact.mesh, capture.cameras, capture.masks);
  for (size_t c = 0; c < views.size(); ++c) {
    const ViewReprojection& v = views[c];
    const std::string& id = capture.cameras[c].id;
    std::printf(
        "  %-10s %7zu px  missed %.3f %% (> 2 px from the outline %.3f %%)  extra %.3f %%\n",
        id.c_str(), v.silhouette_pixels, 100 * v.missed_fraction, 100 * v.missed_far_fraction,
        100 * v.spurious_fraction);
    const auto exception = exceptions.find(id);
    EXPECT_LE(v.missed_far_fraction,
              exception == exceptions.end() ? kCoveringMissedFar : exception->second)
        << id;
  }
}

TEST(RealDataHullTest, CoveringHullOfTheDancer) {
  const std::filesystem::path folder = kData / "inria-dancer-silhouettes";
  SILNET_REQUIRE_REAL_DATA(folder);
  RealCapture capture = LoadInriaDancer(folder);
  for (cv::Mat& mask : capture.masks)
    mask = KeepLargestComponent(mask);
  // dancer0004's streak above the head that no other view confirms (see kDancer4Missed):
  // measured 0.556 % beyond 2 px, with the default contours too.
  CheckCoveringHull(capture, "dancer", true, {{"dancer0004", 0.006}});
}

TEST(RealDataHullTest, CoveringHullOfWd2) {
  const std::filesystem::path folder = kData / "tsinghua-wd2-20cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  // Not closed yet: 20 views of covering contours give 3.4 times the cone faces and more
  // near-degenerate configurations than the gap filler closes, as do the default contours at
  // 0.2-0.4 px tolerance (docs/PERFORMANCE.md); the figures are those of the mesh with its
  // few open edges. Views 01 and 18 miss 0.73 % and 0.72 % beyond 2 px, about as much as
  // with the default contours (0.67 %, 0.72 %): there the given cameras disagree with the
  // masks by more than 2 px, which no contour makes up for.
  CheckCoveringHull(LoadTsinghuaWd2(folder, false), "wd2", false,
                    {{"wd2_01", 0.008}, {"wd2_18", 0.008}});
}

// A small simulated dataset: 6 cameras with fractional time offsets, exact masks.
struct SimulatedDataset {
  silnet::testing::TempDir dir;
  std::vector<CameraModel> cameras;

  SimulatedDataset() {
    sim::SimulationOptions options;
    options.network.cameras = 6;
    options.network.max_offset = 3.0;
    options.network.seed = 7;
    options.frames = 16;
    options.write_frames = false;
    options.threads = 1;
    options.scene.seed = 3;
    cameras = sim::GenerateDataset(options, dir / "data", nullptr).cameras;
  }
  HullSequenceConfig Config(int first, int last) const {
    HullSequenceConfig config;
    config.input = dir / "data";
    config.calibration = dir / "data" / "ground_truth.yaml";
    config.output = dir / "out";
    config.first_frame = first;
    config.last_frame = last;
    config.options.voxel_size = 0.02;
    config.options.threads = 2;
    return config;
  }
};

TEST(HullSequenceJobTest, WritesMeshesIndexAndOverlays) {
  const SimulatedDataset data;
  const size_t reference = ReferenceCameraIndex(data.cameras);
  // The first frame every camera can interpolate, in the reference camera's frames.
  double lowest = 0, highest = 1e9;
  for (const CameraModel& camera : data.cameras) {
    const double ref = data.cameras[reference].time_offset - camera.time_offset;
    lowest = std::max(lowest, -ref);
    highest = std::min(highest, 15 - ref);
  }
  const int first = static_cast<int>(std::ceil(lowest)) + 1;
  ASSERT_LT(first + 3, static_cast<int>(std::floor(highest)));
  HullSequenceConfig config = data.Config(first, first + 3);
  config.options.overlays = true;
  config.options.polyhedral = false;  // carved: the fallback's own path
  Progress progress("hulls", 0);
  const HullSequenceResult result = RunHullSequenceJob(config, &progress);
  EXPECT_TRUE(result.interpolated);
  ASSERT_EQ(result.frames.size(), 3u);
  EXPECT_EQ(result.Succeeded(), 3u);
  EXPECT_TRUE(result.AllClosedManifold());
  EXPECT_EQ(progress.done(), 3u);
  for (const HullFrameResult& f : result.frames) {
    ASSERT_TRUE(f.success) << f.reason;
    EXPECT_EQ(f.method, "voxel");
    const TriangleMesh mesh = ReadPlyMesh((config.output / f.file).string());
    EXPECT_EQ(mesh.triangles.size(), f.triangles);
    EXPECT_GT(f.volume_m3, 0.01);  // a person is some 0.07 m^3
    ASSERT_EQ(f.views.size(), data.cameras.size());
    for (const ViewReprojection& v : f.views) {
      // Exact masks, 2 cm voxels: the cuberille surface misses little and overshoots more.
      // Measured with seed 7: worst view 1.5 %, mean 0.35 %; interpolated silhouettes of
      // different cameras agree less than exact ones (0.3 % worst in subject_hull_test).
      EXPECT_LE(v.missed_fraction, 0.025) << v.camera_id << " frame " << f.frame;
      EXPECT_LE(v.spurious_fraction, 0.25) << v.camera_id << " frame " << f.frame;
      const std::string overlay = "overlays/frame_" + f.file.substr(6, 6) + "_" + v.camera_id;
      EXPECT_TRUE(std::filesystem::exists(config.output / (overlay + ".png"))) << overlay;
    }
  }
  EXPECT_LE(result.MeanMissed(), 0.006);
  std::printf("sequence: %zu frames, mean missed %.3f %%, extra %.3f %%, %.2f s\n",
              result.frames.size(), 100 * result.MeanMissed(), 100 * result.MeanSpurious(),
              result.seconds);

  cv::FileStorage index((config.output / "hulls.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(index.isOpened());
  const cv::FileNode frames = index["frames"];
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(static_cast<int>(frames[0]["frame"]), first);
  EXPECT_EQ(static_cast<std::string>(frames[0]["file"]), result.frames[0].file);
  EXPECT_EQ(static_cast<int>(frames[0]["closed_manifold"]), 1);
  EXPECT_EQ(frames[0]["views"].size(), data.cameras.size());
  EXPECT_NEAR(static_cast<double>(frames[0]["views"][0]["missed_fraction"]),
              result.frames[0].views[0].missed_fraction, 1e-12);
}

// Without a frame range the job builds every reference frame at which each camera has the
// frames it needs (the two its interpolated silhouette blends, or the nearest one), and no
// other: one frame more at either end is refused, the message naming the usable range.
TEST(HullSequenceJobTest, BuildsEveryFrameAllCamerasCoverByDefault) {
  const SimulatedDataset data;
  const size_t reference = ReferenceCameraIndex(data.cameras);
  double lowest = -1e9, highest = 1e9;  // camera frame = reference frame + ref (equal rates)
  for (const CameraModel& camera : data.cameras) {
    const double ref = data.cameras[reference].time_offset - camera.time_offset;
    lowest = std::max(lowest, -ref);
    highest = std::min(highest, 15 - ref);  // camera frames 0..15
  }
  for (const bool interpolate : {true, false}) {
    HullSequenceConfig config = data.Config(0, 0);
    config.every_covered_frame = true;
    config.options.polyhedral = false;
    if (!interpolate) config.options.interpolate = false;
    const HullSequenceResult result = RunHullSequenceJob(config, nullptr);
    EXPECT_EQ(result.interpolated, interpolate);
    ASSERT_FALSE(result.frames.empty());
    const int first = result.frames.front().frame, last = result.frames.back().frame;
    EXPECT_EQ(first, interpolate ? static_cast<int>(std::ceil(lowest))
                                 : static_cast<int>(std::floor(lowest - 0.5)) + 1);
    EXPECT_EQ(last, interpolate ? static_cast<int>(std::floor(highest))
                                : static_cast<int>(std::ceil(highest + 0.5)) - 1);
    EXPECT_EQ(result.Succeeded(), result.frames.size());

    const std::string usable = fmt::format("usable reference frames {}:{}", first, last + 1);
    for (const int outside : {first - 1, last + 1}) {
      HullSequenceConfig one = data.Config(outside, outside + 1);
      one.options = config.options;
      EXPECT_THAT([&] { RunHullSequenceJob(one, nullptr); },
                  ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(usable)))
          << "interpolate " << interpolate << ", frame " << outside;
    }
  }
}

// A camera's mask of frame `k` in a dataset as the Contour record its node would send
// (session 7).
FrameRecord ContourRecord(const DatasetLayout& layout, const CameraModel& camera, int k) {
  const cv::Mat mask = cv::imread(layout.MaskPath(camera.id, k).string(), cv::IMREAD_GRAYSCALE);
  SILNET_CHECK(!mask.empty());
  FrameRecord record;
  record.camera_id = camera.id;
  record.session = 7;
  record.frame_index = static_cast<uint64_t>(k);
  record.width = static_cast<uint16_t>(mask.cols);
  record.height = static_cast<uint16_t>(mask.rows);
  record.payload = EncodeContours(ExtractContours(mask));
  return record;
}

// Writes a session store as the live aggregator holds it: every camera's masks as Contour
// records, frame indices 0..frames-1, minus `skip`.
void WriteContourStore(const std::filesystem::path& dataset,
                       const std::vector<CameraModel>& cameras, int frames,
                       const std::filesystem::path& store, int skip = -1) {
  const DatasetLayout layout(dataset);
  std::filesystem::create_directories(store);
  for (const CameraModel& camera : cameras) {
    RecordLogWriter writer;
    ASSERT_TRUE(writer.Open(SessionLogPath(store, camera.id), kSessionLogStreamKind).ok());
    for (int k = 0; k < frames; ++k) {
      if (k == skip) continue;
      ASSERT_TRUE(writer
                      .Append(static_cast<uint16_t>(SessionRecordType::kContour),
                              SerializeFrameRecord(ContourRecord(layout, camera, k)))
                      .ok());
    }
  }
}

TEST(HullSequenceJobTest, ASessionStoresContoursGiveTheHullsOfTheMasks) {
  const SimulatedDataset data;
  const std::filesystem::path store = data.dir / "store" / "sessions";
  WriteContourStore(data.dir / "data", data.cameras, 16, store);
  const HullSequenceResult from_masks = RunHullSequenceJob(data.Config(5, 8), nullptr);
  HullSequenceConfig config = data.Config(5, 8);
  config.input = data.dir / "store";
  config.output = data.dir / "out-store";
  const HullSequenceResult from_store = RunHullSequenceJob(config, nullptr);
  ASSERT_EQ(from_store.frames.size(), 3u);
  for (size_t f = 0; f < 3; ++f) {
    ASSERT_TRUE(from_store.frames[f].success) << from_store.frames[f].reason;
    // Contours simplified at 0.5 px move the boundary by a fraction of a pixel: the hulls
    // agree to a few per cent of volume.
    EXPECT_NEAR(from_store.frames[f].volume_m3, from_masks.frames[f].volume_m3,
                0.03 * from_masks.frames[f].volume_m3);
  }
  EXPECT_LE(from_store.MeanMissed(), 0.01);
  std::printf("session store hulls: missed %.3f %% (masks %.3f %%)\n",
              100 * from_store.MeanMissed(), 100 * from_masks.MeanMissed());
}

TEST(HullSequenceJobTest, ContoursHeldInMemoryGiveTheHullsOfTheStore) {
  const SimulatedDataset data;
  const std::filesystem::path store = data.dir / "store" / "sessions";
  WriteContourStore(data.dir / "data", data.cameras, 16, store);
  HullSequenceConfig config = data.Config(5, 8);
  config.input = data.dir / "store";
  const HullSequenceResult from_store = RunHullSequenceJob(config, nullptr);
  // As the live job holds them: only the frames the batch needs, the rest dropped.
  RecentContours held(store);
  const DatasetLayout layout(data.dir / "data");
  for (const CameraModel& camera : data.cameras) {
    for (int k = 0; k < 16; ++k)
      held.Add(ContourRecord(layout, camera, k));
    held.DropBefore(camera.id, 1);
  }
  config.output = data.dir / "out-memory";
  const HullSequenceResult from_memory = RunHullSequenceJob(config, held, nullptr);
  ASSERT_EQ(from_memory.frames.size(), from_store.frames.size());
  for (size_t f = 0; f < from_store.frames.size(); ++f) {
    ASSERT_TRUE(from_memory.frames[f].success) << from_memory.frames[f].reason;
    EXPECT_EQ(from_memory.frames[f].triangles, from_store.frames[f].triangles);
    EXPECT_EQ(from_memory.frames[f].volume_m3, from_store.frames[f].volume_m3);
  }
  // A frame the batch needs that was dropped is a clear error, not a hole in the hull.
  for (const CameraModel& camera : data.cameras)
    held.DropBefore(camera.id, 8);
  EXPECT_THAT([&] { RunHullSequenceJob(config, held, nullptr); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("in memory")))
      << "the frames were dropped";
}

TEST(HullSequenceJobTest, AFrameWithoutContourIsAClearError) {
  const SimulatedDataset data;
  WriteContourStore(data.dir / "data", data.cameras, 16, data.dir / "store", 6);
  HullSequenceConfig config = data.Config(5, 8);
  config.input = data.dir / "store";
  config.options.interpolate = false;
  EXPECT_THAT([&] { RunHullSequenceJob(config, nullptr); },
              ::testing::ThrowsMessage<InputError>(
                  ::testing::HasSubstr("frame 6 of session 7 has no contour")))
      << "frame 6 is missing";
}

TEST(HullSequenceJobTest, ByDefaultWritesClosedExactPolyhedralHulls) {
  const SimulatedDataset data;
  const HullSequenceConfig config = data.Config(4, 7);
  ASSERT_TRUE(config.options.polyhedral);
  const HullSequenceResult result = RunHullSequenceJob(config, nullptr);
  ASSERT_EQ(result.frames.size(), 3u);
  for (const HullFrameResult& frame : result.frames) {
    ASSERT_TRUE(frame.success) << frame.reason;
    EXPECT_EQ(frame.method, "polyhedral") << frame.polyhedral_failure;
    EXPECT_TRUE(frame.closed_manifold);
    const TriangleMesh mesh = ReadPlyMesh((config.output / frame.file).string());
    EXPECT_NEAR(MeshVolume(mesh), frame.volume_m3, 1e-6);
    for (const ViewReprojection& view : frame.views)
      EXPECT_LE(view.missed_fraction, 0.02) << view.camera_id << " frame " << frame.frame;
  }
  cv::FileStorage index((config.output / "hulls.yaml").string(), cv::FileStorage::READ);
  EXPECT_EQ(static_cast<std::string>(index["frames"][0]["method"]), "polyhedral");
}

TEST(HullSequenceJobTest, LeavesOutCamerasTheCalibrationCouldNotPlace) {
  const SimulatedDataset data;
  std::vector<CameraModel> placed = data.cameras;
  placed.erase(placed.begin() + 4);  // as if the calibration had not placed cam04
  HullSequenceConfig config = data.Config(8, 9);
  config.calibration = data.dir / "placed.yaml";
  SaveCalibration(config.calibration, placed);
  const HullSequenceResult result = RunHullSequenceJob(config, nullptr);
  ASSERT_EQ(result.frames.size(), 1u);
  ASSERT_TRUE(result.frames[0].success) << result.frames[0].reason;
  ASSERT_EQ(result.frames[0].views.size(), placed.size());
  for (const ViewReprojection& v : result.frames[0].views) {
    EXPECT_NE(v.camera_id, "cam04");
    EXPECT_LE(v.missed_fraction, 0.025) << v.camera_id;
  }
}

TEST(HullSequenceJobTest, ReportsUnusableInputClearly) {
  const SimulatedDataset data;
  const auto refused = [](const HullSequenceConfig& config, const std::string& fragment) {
    EXPECT_THAT([&] { RunHullSequenceJob(config, nullptr); },
                ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(fragment)));
  };
  refused(data.Config(14, 40), "out of range");
  refused(data.Config(3, 3), "empty");

  std::vector<CameraModel> renamed = data.cameras;
  renamed[1].id = "elsewhere";
  HullSequenceConfig config = data.Config(5, 6);
  config.calibration = data.dir / "renamed.yaml";
  SaveCalibration(config.calibration, renamed);
  refused(config, "camera elsewhere");

  std::vector<CameraModel> resized = data.cameras;
  resized[2].width += 2;
  config.calibration = data.dir / "resized.yaml";
  SaveCalibration(config.calibration, resized);
  refused(config, "but the calibration of");
}

}  // namespace
}  // namespace silnet::aggregator
