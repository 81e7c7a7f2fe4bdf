// The Middlebury measures and silhouette consistency on analytic shapes (a sphere mesh
// against points on the same sphere, on a larger one, and against its exact mask), and the
// stereo job end to end on small simulated stills: the model is written closed and is more
// accurate than the visual hull; stereo.yaml holds the figures; the CLI rejects a missing
// calibration with a clear message.

#include "aggregator/stereo/stereo_job.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/nearest_point.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/model_render.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"
#include "sim/stills_generator.h"
#include "tests/aggregator/stereo/test_spheres.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

const Eigen::Vector3d kCentre(0.1, -0.2, 1.0);
using testing::Icosphere;

// Uniform random points on a sphere with outward normals.
void SpherePoints(double radius, size_t count, std::vector<Eigen::Vector3d>* points,
                  std::vector<Eigen::Vector3d>* normals) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0, 1);
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d n = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    points->push_back(kCentre + radius * n);
    normals->push_back(n);
  }
}

TEST(NearestPointTest, FindsTheNearestPointsInOrder) {
  const NearestPoint tree({{0, 0, 0}, {1, 0, 0}, {0, 2, 0}});
  std::vector<int> indices;
  std::vector<double> distances;
  tree.KNearest({{0.9, 0, 0}}, 4, &indices, &distances);
  ASSERT_EQ(indices.size(), 4u);
  EXPECT_EQ(indices[0], 1);
  EXPECT_EQ(indices[1], 0);
  EXPECT_EQ(indices[2], 2);
  EXPECT_EQ(indices[3], -1);
  EXPECT_NEAR(distances[0], 0.1, 1e-6);
  EXPECT_TRUE(std::isinf(distances[3]));
  EXPECT_TRUE(std::isinf(NearestPoint({}).Distances({{0, 0, 0}})[0]));
}

TEST(NearestPointTest, ManyQueriesOnTwoThreadsGiveTheExactNearestPointsOfOne) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<Eigen::Vector3d> points(5000), queries(20000);  // queries: several tasks
  for (auto* set : {&points, &queries}) {
    for (Eigen::Vector3d& p : *set)
      p = {uniform(rng), uniform(rng), uniform(rng)};
  }
  for (size_t q = 0; q < queries.size(); q += 3)
    queries[q] *= 2.5;  // many beyond the points' box, where the search order clamps them
  std::vector<int> one_indices, two_indices;
  std::vector<double> one_distances, two_distances;
  NearestPoint(points, 1).KNearest(queries, 3, &one_indices, &one_distances);
  NearestPoint(points, 2).KNearest(queries, 3, &two_indices, &two_distances);
  EXPECT_EQ(one_indices, two_indices);
  EXPECT_EQ(one_distances, two_distances);
  // Against brute force on every 97th query: the same nearest point, its distance in float.
  for (size_t q = 0; q < queries.size(); q += 97) {
    size_t best = 0;
    for (size_t i = 1; i < points.size(); ++i) {
      if ((points[i] - queries[q]).squaredNorm() < (points[best] - queries[q]).squaredNorm())
        best = i;
    }
    EXPECT_EQ(two_indices[3 * q], static_cast<int>(best)) << q;
    EXPECT_NEAR(two_distances[3 * q], (points[best] - queries[q]).norm(), 1e-6) << q;
    EXPECT_LE(two_distances[3 * q], two_distances[3 * q + 1]);
    EXPECT_LE(two_distances[3 * q + 1], two_distances[3 * q + 2]);
  }
}

TEST(ModelEvaluationTest, SphereAgainstItselfAndALargerSphere) {
  const double radius = 0.1, footprint = 0.005;
  const TriangleMesh sphere = Icosphere(kCentre, radius, 5);
  ModelEvaluationOptions options;
  options.footprint = footprint;
  options.completeness_footprints = {1.0, 3.0};
  std::vector<Eigen::Vector3d> points, normals;
  SpherePoints(radius, 40000, &points, &normals);  // about 2 mm apart
  const ModelEvaluation same = EvaluateModel(sphere, points, normals, options);
  std::printf("[ evaluation ] same sphere: %s (truth spacing %.2f mm, %zu samples)\n",
              same.Brief().c_str(), same.truth_spacing * 1e3, same.model_samples);
  EXPECT_LT(same.accuracy_m, 2e-4);
  EXPECT_NEAR(same.accuracy_footprints, same.accuracy_m / footprint, 1e-12);
  EXPECT_GT(same.completeness[0].fraction, 0.999);
  EXPECT_EQ(same.completeness[1].fraction, 1.0);
  // Half a footprint apart by default: 4 pi r^2 / (2.5 mm)^2 samples.
  EXPECT_NEAR(static_cast<double>(same.model_samples), 4 * M_PI * radius * radius / 6.25e-6, 200);

  std::vector<Eigen::Vector3d> larger, larger_normals;
  SpherePoints(radius + 0.01, 40000, &larger, &larger_normals);
  const ModelEvaluation off = EvaluateModel(sphere, larger, larger_normals, options);
  std::printf("[ evaluation ] sphere 1 cm larger: %s\n", off.Brief().c_str());
  EXPECT_NEAR(off.accuracy_m, 0.01, 5e-4);
  EXPECT_NEAR(off.mean_distance_m, 0.01, 5e-4);
  EXPECT_EQ(off.completeness[0].fraction, 0.0);  // within 5 mm
  EXPECT_EQ(off.completeness[1].fraction, 1.0);  // within 15 mm

  // Deterministic for a seed, and one prepared truth serves several models with the figures
  // of a truth prepared per call.
  EXPECT_EQ(EvaluateModel(sphere, larger, larger_normals, options).accuracy_m, off.accuracy_m);
  const TruthSurface shared(larger, larger_normals, 0.0, 2);
  EXPECT_EQ(shared.spacing(), off.truth_spacing);
  const TriangleMesh coarser = Icosphere(kCentre, radius, 3);
  for (const TriangleMesh* mesh : {&sphere, &coarser}) {
    const ModelEvaluation once = EvaluateModel(*mesh, larger, larger_normals, options);
    const ModelEvaluation reused = EvaluateModel(*mesh, shared, options);
    EXPECT_EQ(reused.accuracy_m, once.accuracy_m);
    EXPECT_EQ(reused.mean_distance_m, once.mean_distance_m);
    EXPECT_EQ(reused.completeness[0].fraction, once.completeness[0].fraction);
    EXPECT_EQ(reused.completeness[1].fraction, once.completeness[1].fraction);
  }
  ModelEvaluationOptions bad;
  std::string reason;
  EXPECT_FALSE(bad.IsValid(&reason));
  EXPECT_EQ(reason, "the footprint must be positive");
}

TEST(ModelEvaluationTest, RegionMeasuresOnlyItsPartOfTheSurface) {
  const double radius = 0.1, footprint = 0.005;
  const TriangleMesh sphere = Icosphere(kCentre, radius, 5);
  ModelEvaluationOptions options;
  options.footprint = footprint;
  options.completeness_footprints = {1.0, 3.0};
  // The truth's upper half lies 1 cm beyond the model; the region is that half.
  std::vector<Eigen::Vector3d> points, normals;
  SpherePoints(radius, 40000, &points, &normals);
  SurfaceRegion upper{"upper", std::vector<uint8_t>(points.size(), 0)};
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].z() <= kCentre.z()) continue;
    upper.truth[i] = 1;
    points[i] += 0.01 * normals[i];
  }
  ModelDistances distances;
  const ModelEvaluation e = EvaluateModel(sphere, points, normals, options, {upper}, &distances);
  const RegionEvaluation* region = e.Region("upper");
  ASSERT_NE(region, nullptr);
  std::printf("[ evaluation ] region: %s\n", region->Brief().c_str());
  EXPECT_NEAR(static_cast<double>(region->truth_points), 20000, 600);
  EXPECT_NEAR(region->accuracy_m, 0.01, 1e-3);
  EXPECT_EQ(region->completeness[0].fraction, 0.0);
  EXPECT_GT(region->completeness[1].fraction, 0.99);
  EXPECT_NEAR(e.completeness[0].fraction, 0.5, 0.03);
  ASSERT_EQ(distances.truth_to_model.size(), points.size());
  for (size_t i = 0; i < points.size(); i += 97) {
    // Away from the equator: upper points 1 cm off, lower ones on the model (up to the gaps
    // of its random sample).
    const double height = points[i].z() - kCentre.z();
    if (height > 0.02) {
      EXPECT_NEAR(distances.truth_to_model[i], 0.01, 5e-4);
    } else if (height < -0.02) {
      EXPECT_LT(distances.truth_to_model[i], 2e-3);
    }
  }
}

// The exact silhouette of a sphere: pixel centres whose rays meet it.
cv::Mat SphereMask(const CameraModel& camera, const Eigen::Vector3d& centre, double radius) {
  cv::Mat mask(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  const Eigen::Vector3d c = camera.Center();
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray =
          (camera.R.transpose() * camera.K.inverse() * Eigen::Vector3d(x, y, 1)).normalized();
      const Eigen::Vector3d to = centre - c;
      const double miss = (to - to.dot(ray) * ray).norm();
      if (miss < radius) mask.at<uint8_t>(y, x) = 255;
    }
  }
  return mask;
}

// A camera 320x240 at `position` looking at kCentre.
CameraModel CameraLookingAtCentre(const Eigen::Vector3d& position) {
  CameraModel camera;
  camera.id = "cam";
  camera.width = 320;
  camera.height = 240;
  camera.K << 400, 0, 159.5, 0, 400, 119.5, 0, 0, 1;
  camera.R = LookAtRotation(position, kCentre, Eigen::Vector3d(0, 0, 1));
  camera.t = -camera.R * position;
  return camera;
}

// Grey level of a BGR pixel.
int Brightness(const cv::Mat& image, const Eigen::Vector2d& pixel) {
  const cv::Vec3b bgr = image.at<cv::Vec3b>(static_cast<int>(std::lround(pixel.y())),
                                            static_cast<int>(std::lround(pixel.x())));
  return (bgr[0] + bgr[1] + bgr[2]) / 3;
}

TEST(ModelEvaluationTest, SphereMeshIsConsistentWithItsExactSilhouette) {
  const double radius = 0.1;
  StereoView view;
  view.camera = CameraLookingAtCentre(Eigen::Vector3d(0.7, 0.1, 0.4));
  view.mask = SphereMask(view.camera, kCentre, radius);

  const TriangleMesh sphere = Icosphere(kCentre, radius, 5);
  const SilhouetteConsistency exact = MeasureSilhouetteConsistency(sphere, {view})[0];
  std::printf(
      "[ silhouettes ] sphere: %zu pixels, missed %zu (>= 1 px inside: %zu of %zu), "
      "covered outside %zu (>= 1 px: %zu)\n",
      exact.silhouette_pixels, exact.missed_pixels, exact.missed_inner, exact.inner_pixels,
      exact.covered_background, exact.covered_outer);
  EXPECT_EQ(exact.camera_id, "cam");
  EXPECT_GT(exact.silhouette_pixels, 5000u);
  EXPECT_GT(exact.inner_pixels, exact.silhouette_pixels * 9 / 10);
  EXPECT_LT(exact.inner_pixels, exact.silhouette_pixels);
  EXPECT_EQ(exact.missed_inner, 0u);
  EXPECT_EQ(exact.covered_outer, 0u);

  // 1 cm larger (about 4 px here) covers pixels beyond the margin; 1 cm smaller misses some.
  const SilhouetteConsistency larger =
      MeasureSilhouetteConsistency(Icosphere(kCentre, radius + 0.01, 5), {view})[0];
  EXPECT_GT(larger.covered_outer, 100u);
  EXPECT_EQ(larger.missed_inner, 0u);
  const SilhouetteConsistency smaller =
      MeasureSilhouetteConsistency(Icosphere(kCentre, radius - 0.01, 5), {view})[0];
  EXPECT_GT(smaller.missed_inner, 100u);
  EXPECT_EQ(smaller.covered_outer, 0u);
}

TEST(ModelRenderTest, ShadedRenderCoversTheSilhouetteAndHidesFartherSurfaces) {
  const CameraModel camera = CameraLookingAtCentre(Eigen::Vector3d(0.7, 0.1, 0.4));
  const TriangleMesh sphere = Icosphere(kCentre, 0.1, 5);
  const cv::Mat shaded = RenderShadedMesh(sphere, camera);
  ASSERT_EQ(shaded.type(), CV_8UC3);
  ASSERT_EQ(shaded.size(), cv::Size(320, 240));
  // Drawn pixels: the mesh's silhouette up to a pixel along its outline.
  cv::Mat gray;
  cv::cvtColor(shaded, gray, cv::COLOR_BGR2GRAY);
  const cv::Mat drawn = gray != 45;
  const cv::Mat coverage = RenderMeshSilhouette(sphere, camera);
  cv::Mat inner, outer;
  cv::erode(coverage, inner, cv::Mat());
  cv::dilate(coverage, outer, cv::Mat());
  EXPECT_GT(cv::countNonZero(coverage), 5000);
  EXPECT_EQ(cv::countNonZero(inner & ~drawn), 0);
  EXPECT_EQ(cv::countNonZero(drawn & ~outer), 0);
  // Facing the camera is bright, grazing the outline dark.
  const Eigen::Vector2d centre = *camera.Project(kCentre);
  EXPECT_GT(Brightness(shaded, centre), 150);

  // A small sphere on the ray through the big one's grazing rim, nearer the camera: its
  // facing centre hides the dark rim whatever order the triangles come in.
  const Eigen::Vector3d towards_camera = (camera.Center() - kCentre).normalized();
  const Eigen::Vector3d sideways = towards_camera.cross(Eigen::Vector3d(0, 0, 1)).normalized();
  const Eigen::Vector3d rim = kCentre + 0.098 * sideways;
  const Eigen::Vector3d small_centre = camera.Center() + 0.7 * (rim - camera.Center());
  TriangleMesh both = Icosphere(small_centre, 0.02, 4);
  const auto offset = static_cast<int32_t>(both.vertices.size());
  for (const auto& v : sphere.vertices)
    both.vertices.push_back(v);
  for (const auto& t : sphere.triangles)
    both.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const Eigen::Vector2d pixel = *camera.Project(rim);
  EXPECT_LT(Brightness(shaded, pixel), 120);
  EXPECT_GT(Brightness(RenderShadedMesh(both, camera), pixel), 150);
}

// Small stills, made once: 8 cameras at 480x360 (at 320x240 the baseline cut's model is
// less accurate than the hull; docs/PERFORMANCE.md).
const std::filesystem::path& SmallStills() {
  static silnet::testing::TempDir dir;
  static const bool made = [] {
    sim::StillsOptions options;
    options.network.cameras = 8;
    options.network.width = 480;
    options.network.height = 360;
    sim::GenerateStills(options, dir.path(), nullptr);
    return true;
  }();
  EXPECT_TRUE(made);
  return dir.path();
}

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The job's settings for stills in `input` (with their calibration.yaml) written to `output`.
StereoJobConfig ConfigFor(const std::filesystem::path& input, const std::filesystem::path& output) {
  StereoJobConfig config;
  config.input = input;
  config.calibration = input / "calibration.yaml";
  config.output = output;
  return config;
}

// With the silhouette steps' cells joined to the model and the pieces no pixel needs removed
// (--silhouette-join-steps 3 --remove-redundant-pieces), the small stills' model keeps a few
// of its floating pieces, still covers every inner silhouette pixel and no outer one, and is
// as accurate as the issue asks. Measured: 176 pieces, 157 removed; 1.07 fp, 97.9 % within
// 2 fp (without the options 240 pieces, 1.07 fp, 98.6 %).
TEST(StereoJobTest, JoinedCellsAndRemovedPiecesLeaveFewPiecesAndTheSameSilhouettes) {
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(SmallStills(), out.path());
  config.graph_cut.silhouette_join_steps = 3;
  config.remove_redundant_pieces = true;
  const StereoJobResult result = RunStereoJob(config, nullptr);
  ASSERT_TRUE(result.success) << result.reason;
  ASSERT_TRUE(result.redundant_pieces && result.model.evaluation);
  const RedundantPieceStats& pieces = *result.redundant_pieces;
  std::printf("[ stereo job ] joined %zu pixels' cells; %zu of %zu pieces removed; model: %s\n",
              result.graph_cut.joined_pixels, pieces.removed, pieces.pieces_before,
              result.model.evaluation->Brief().c_str());
  EXPECT_GT(result.graph_cut.joined_pixels, 0u);
  EXPECT_EQ(result.model.pieces, pieces.pieces_before - pieces.removed);
  EXPECT_GE(10 * pieces.removed, 8 * pieces.pieces_before);
  EXPECT_TRUE(result.model.closed_manifold);
  EXPECT_EQ(result.model.MissedInner(), 0u);
  EXPECT_EQ(result.model.CoveredOuter(), 0u);
  EXPECT_LT(result.model.evaluation->accuracy_footprints, 1.5);
  EXPECT_GE(result.model.evaluation->completeness[1].fraction, 0.97);
  cv::FileStorage fs((out.path() / "stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_EQ(static_cast<int>(fs["redundant_pieces"]["removed"]), static_cast<int>(pieces.removed));
  EXPECT_EQ(static_cast<int>(fs["graph"]["joined_pixels"]),
            static_cast<int>(result.graph_cut.joined_pixels));
}

TEST(StereoJobTest, SimulatedStillsGiveAClosedModelMoreAccurateThanTheHull) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(input, out.path());
  Progress progress("stereo", 0);
  const auto start = std::chrono::steady_clock::now();
  const StereoJobResult result = RunStereoJob(config, &progress);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(result.success) << result.reason;
  EXPECT_EQ(result.views, 8u);
  ASSERT_TRUE(result.model.evaluation && result.hull.evaluation);
  const ModelEvaluation& model = *result.model.evaluation;
  const ModelEvaluation& hull = *result.hull.evaluation;
  std::printf("[ stereo job ] %.1f s; model: %s; hull: %s\n", seconds, model.Brief().c_str(),
              hull.Brief().c_str());
  // Measured: model 1.07 fp, 93.6 / 98.6 % within 1 / 2 fp; the graph cut's surface before
  // the local refinement 1.4 fp, 98.7 % within 2 fp (2.5 fp, 53 % without the silhouette
  // step); hull 4.3 fp, 94 %.
  EXPECT_LT(model.accuracy_footprints, 0.5 * hull.accuracy_footprints);
  EXPECT_LT(model.accuracy_footprints, 2.0);
  EXPECT_GT(model.completeness[1].fraction, 0.95);
  EXPECT_GT(hull.completeness[1].fraction, 0.9);
  EXPECT_GT(result.footprint, 0.0);

  const TriangleMesh written = ReadPlyMesh((out / "model.ply").string());
  EXPECT_EQ(written.triangles.size(), result.model.triangles);
  EXPECT_TRUE(CheckClosedManifold(written).closed_manifold);
  EXPECT_TRUE(std::filesystem::exists(out / "hull.ply"));
  // The refinement improves on the cut, both measured.
  ASSERT_TRUE(result.refinement && result.cut.evaluation);
  EXPECT_LT(model.accuracy_footprints, result.cut.evaluation->accuracy_footprints);
  EXPECT_GT(model.completeness[0].fraction, result.cut.evaluation->completeness[0].fraction);
  EXPECT_EQ(ReadPlyMesh((out / "cut.ply").string()).triangles.size(), result.cut.triangles);
  // The exact hull explains every silhouette; the model lies inside it.
  ASSERT_EQ(result.model.views.size(), 8u);
  for (size_t v = 0; v < 8; ++v) {
    EXPECT_EQ(result.hull.views[v].covered_outer, 0u) << v;
    EXPECT_EQ(result.model.views[v].covered_outer, 0u) << v;
  }

  cv::FileStorage fs((out / "stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_EQ(static_cast<int>(fs["success"]), 1);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["settings"]["lambda"]), 3.0);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["settings"]["ballooning"]), 0.1);
  EXPECT_EQ(fs["lattice"]["dims"].size(), 3u);
  EXPECT_GT(static_cast<int>(fs["graph"]["nodes"]), 0);
  EXPECT_GT(static_cast<double>(fs["seconds"]["photo_consistency"]), 0.0);
  EXPECT_GT(static_cast<double>(fs["seconds"]["refinement"]), 0.0);
  EXPECT_EQ(static_cast<int>(fs["refinement"]["iterations"]), 6);
  EXPECT_GT(static_cast<int>(fs["refinement"]["vertices"]),
            static_cast<int>(fs["refinement"]["vertices_in"]));
  EXPECT_NEAR(static_cast<double>(fs["cut"]["evaluation"]["accuracy_footprints"]),
              result.cut.evaluation->accuracy_footprints, 1e-9);
  EXPECT_EQ(fs["silhouettes"].size(), 8u);
  EXPECT_NEAR(static_cast<double>(fs["model"]["evaluation"]["accuracy_footprints"]),
              model.accuracy_footprints, 1e-9);
  EXPECT_NEAR(static_cast<double>(fs["hull"]["evaluation"]["accuracy_mm"]), hull.accuracy_m * 1e3,
              1e-9);
  EXPECT_NEAR(static_cast<double>(fs["model"]["evaluation"]["completeness"][1]["fraction"]),
              model.completeness[1].fraction, 1e-9);

  // One picture per view, three equal panels (photo | render | silhouette comparison), and
  // the report links them all.
  const std::string report = ReadText(out / "report.html");
  EXPECT_NE(report.find("closed and manifold"), std::string::npos);
  // The 3D view of the model and the hull (drawn in Chromium by the report tests).
  EXPECT_NE(report.find("data-viewer-state"), std::string::npos);
  for (const char* file : {"three.min.js", "OrbitControls.js", "model.js", "hull.js"})
    EXPECT_TRUE(std::filesystem::exists(out / "viewer" / file)) << file;
  ASSERT_EQ(result.view_pictures.size(), 8u);
  for (const std::string& file : result.view_pictures) {
    const cv::Mat picture = cv::imread((out / file).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(picture.empty()) << file;
    EXPECT_EQ(picture.cols % 3, 0) << file;
    EXPECT_GT(picture.rows, 100) << file;
    EXPECT_NE(report.find(fmt::format("src=\"{}\"", file)), std::string::npos) << file;
  }
}

// Inner silhouette pixels over all views of `mesh`.
size_t InnerPixels(const StereoMeshSummary& mesh) {
  size_t inner = 0;
  for (const SilhouetteConsistency& view : mesh.views)
    inner += view.inner_pixels;
  return inner;
}

// Simulated 640x480 stills of 16 cameras in `layout`, made once per layout.
const std::filesystem::path& SixteenViewStills(sim::RigLayout layout) {
  static std::map<sim::RigLayout, silnet::testing::TempDir> dirs;
  const auto [it, made] = dirs.try_emplace(layout);
  if (made) {
    sim::StillsOptions options;  // 16 cameras, 640x480
    options.network.layout = layout;
    sim::GenerateStills(options, it->second.path(), nullptr);
  }
  return it->second.path();
}

// The job (uniform lattice) on the stills of SixteenViewStills(layout), run once per layout
// and shared by the tests that check it and compare with it.
const StereoJobResult& UniformSixteenViews(sim::RigLayout layout) {
  static std::map<sim::RigLayout, StereoJobResult> results;
  const auto [it, made] = results.try_emplace(layout);
  if (made) {
    silnet::testing::TempDir out;
    it->second = RunStereoJob(ConfigFor(SixteenViewStills(layout), out.path()), nullptr);
  }
  return it->second;
}

// UniformSixteenViews(layout), checked against the targets: accuracy <= 1.5
// footprints, completeness within 2 footprints >= 97 %, exactly silhouette-consistent (every
// silhouette pixel >= 1 px inside the outline covered, none >= 1 px outside it), and in the
// concave region (the true surface the hull misses by > 2 fp) far
// better than the hull.
const StereoJobResult& CheckedSixteenViews(sim::RigLayout layout) {
  const StereoJobResult& result = UniformSixteenViews(layout);
  EXPECT_TRUE(result.success) << result.reason;
  if (!result.success) return result;
  EXPECT_TRUE(result.model.evaluation && result.hull.evaluation);
  if (!result.model.evaluation || !result.hull.evaluation) return result;
  const ModelEvaluation& model = *result.model.evaluation;
  const ModelEvaluation& hull = *result.hull.evaluation;
  std::printf("[ stereo job ] %s: model: %s; hull: %s; %s\n", sim::ToString(layout).c_str(),
              model.Brief().c_str(), hull.Brief().c_str(), result.graph_cut.Brief().c_str());
  EXPECT_LE(model.accuracy_footprints, 1.5);
  EXPECT_GE(model.completeness[1].fraction, 0.97);
  EXPECT_GT(InnerPixels(result.model), 100000u);
  EXPECT_EQ(result.model.MissedInner(), 0u);
  EXPECT_EQ(result.model.CoveredOuter(), 0u);
  const RegionEvaluation* concave = model.Region(kConcaveRegion);
  const RegionEvaluation* hull_concave = hull.Region(kConcaveRegion);
  const RegionEvaluation* junctions = model.Region(kTJunctionRegion);
  EXPECT_TRUE(concave && hull_concave && junctions);
  if (!concave || !hull_concave || !junctions) return result;
  std::printf("[ stereo job ] concave: model %s; hull %s\n", concave->Brief().c_str(),
              hull_concave->Brief().c_str());
  std::printf("[ stereo job ] T-junctions: model %s\n", junctions->Brief().c_str());
  EXPECT_GT(concave->truth_points, 1000u);
  EXPECT_LT(concave->accuracy_footprints, 0.5 * hull_concave->accuracy_footprints);
  EXPECT_GT(concave->completeness[1].fraction, 0.7);
  EXPECT_EQ(hull_concave->completeness[1].fraction, 0.0);
  // No sheets or spikes where the silhouettes have T-junctions: within 2x the whole model.
  EXPECT_GT(junctions->truth_points, 500u);
  EXPECT_LE(junctions->accuracy_footprints, 2 * model.accuracy_footprints);
  return result;
}

// The adaptive tetrahedral method (thesis ch. 7, --method adaptive) on the same stills: a
// closed model that explains its silhouettes and beats the hull, at least as accurate as the
// uniform lattice on these few small views, also in the concavities, and the local refinement
// improves on its cut. With 8 views the first cut misses 24 % of the inner silhouette pixels,
// so the ballooning is raised once (x1.5; 9 % missed after). Measured 2026-11-27: 0.88 fp,
// 93.6 / 98.0 % within 1 / 2 fp, concave region 4.9 fp (without the raise 1.06 fp and 13.5 fp;
// uniform 1.07 fp, 5.3 fp; hull 4.29 fp, 20.5 fp; docs/PERFORMANCE.md).
TEST(StereoJobTest, AdaptiveMethodGivesAClosedSilhouetteConsistentModel) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(input, out.path());
  config.method = StereoMethod::kAdaptive;
  const StereoJobResult result = RunStereoJob(config, nullptr);
  ASSERT_TRUE(result.success) << result.reason;
  ASSERT_TRUE(result.adaptive && result.model.evaluation && result.hull.evaluation);
  EXPECT_TRUE(result.model.closed_manifold);
  size_t inner = 0;
  for (const SilhouetteConsistency& view : result.model.views)
    inner += view.inner_pixels;
  const ModelEvaluation& model = *result.model.evaluation;
  std::printf("[ stereo job, adaptive ] %zu cells; missed %zu of %zu inner pixels; model: %s\n",
              result.adaptive->cells, result.model.MissedInner(), inner, model.Brief().c_str());
  EXPECT_LT(result.model.MissedInner() * 500, inner);
  EXPECT_LT(model.accuracy_footprints, result.hull.evaluation->accuracy_footprints);
  EXPECT_LE(model.accuracy_footprints, 1.0);
  EXPECT_GE(model.completeness[1].fraction, 0.97);
  EXPECT_GT(result.adaptive->ballooning_factor, 1.0);
  ASSERT_GE(result.adaptive->missed_share.size(), 2u);
  EXPECT_GT(result.adaptive->missed_share.front(), 0.2);
  EXPECT_LE(result.adaptive->missed_share.back(), 0.2);
  const RegionEvaluation* concave = model.Region(kConcaveRegion);
  const RegionEvaluation* hull_concave = result.hull.evaluation->Region(kConcaveRegion);
  ASSERT_TRUE(concave && hull_concave);
  std::printf("[ stereo job, adaptive ] concave: model %s; hull %s\n", concave->Brief().c_str(),
              hull_concave->Brief().c_str());
  EXPECT_LT(concave->accuracy_footprints, 0.4 * hull_concave->accuracy_footprints);
  ASSERT_TRUE(result.cut.evaluation);
  std::printf("[ stereo job, adaptive ] the cut before refinement: %s\n",
              result.cut.evaluation->Brief().c_str());
  EXPECT_LT(model.accuracy_footprints, result.cut.evaluation->accuracy_footprints);
  EXPECT_GT(model.completeness[0].fraction, result.cut.evaluation->completeness[0].fraction);
  EXPECT_NE(ReadText(out.path() / "stereo.yaml").find("adaptive"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out.path() / "model.ply"));
}

// The configuration: a ring of 16 cameras at 640x480. The silhouette step makes the
// cut cover its silhouettes, which also brings back the thin parts the plain cut shrinks
// away (measured: accuracy 1.26 -> 1.02 fp, completeness within 2 fp 85 -> 99.2 %, missed
// inner silhouette pixels 18662 -> 0 of ~210k; concave region 1.86 fp against the hull's 16.3);
// the local refinement then 0.67 fp, 97.8 / 99.5 % within 1 / 2 fp, concave region 1.56 fp
// (docs/PERFORMANCE.md).
TEST(StereoJobTest, SixteenViewRingMeetsTheAccuracyTargetsAndCoversItsSilhouettes) {
  const StereoJobResult& result = CheckedSixteenViews(sim::RigLayout::kRing);
  ASSERT_TRUE(result.success && result.model.evaluation && result.hull.evaluation);
  EXPECT_LT(result.model.evaluation->accuracy_footprints,
            0.6 * result.hull.evaluation->accuracy_footprints);
  ASSERT_FALSE(result.graph_cut.missed_pixels_per_round.empty());
  EXPECT_GT(result.graph_cut.missed_pixels_per_round.front(), 10000u);
}

// Issue 18's acceptance on the ring: the adaptive method at least as accurate as the uniform
// lattice and as complete within 2 footprints, as exactly silhouette-consistent up to a few
// pixels, in one piece with the statue's one through-hole (the arm loop) plus at most a few
// specks (measured 2026-11-26: adaptive 0.53 fp, 97.6 / 99.5 % within 1 / 2 fp, 1 inner pixel
// missed of ~210 k, 14 pieces, genus 1; uniform 0.67 fp, 97.8 / 99.5 %, 171 pieces, genus 2).
TEST(StereoJobTest, SixteenViewRingAdaptiveMethodIsAtLeastAsGoodAsTheUniformLattice) {
  const std::filesystem::path& input = SixteenViewStills(sim::RigLayout::kRing);
  silnet::testing::TempDir adaptive_out;
  const StereoJobResult& uniform = UniformSixteenViews(sim::RigLayout::kRing);
  StereoJobConfig config = ConfigFor(input, adaptive_out.path());
  config.method = StereoMethod::kAdaptive;
  const StereoJobResult adaptive = RunStereoJob(config, nullptr);
  ASSERT_TRUE(uniform.success && adaptive.success) << uniform.reason << adaptive.reason;
  ASSERT_TRUE(uniform.model.evaluation && adaptive.model.evaluation && adaptive.hull.evaluation);
  const ModelEvaluation& a = *adaptive.model.evaluation;
  const ModelEvaluation& u = *uniform.model.evaluation;
  std::printf(
      "[ stereo job ] ring, adaptive: %s; %zu pieces, genus %ld, missed %zu / covered %zu\n",
      a.Brief().c_str(), adaptive.model.pieces, adaptive.model.main_genus,
      adaptive.model.MissedInner(), adaptive.model.CoveredOuter());
  std::printf("[ stereo job ] ring, uniform: %s; %zu pieces, genus %ld\n", u.Brief().c_str(),
              uniform.model.pieces, uniform.model.main_genus);
  EXPECT_LE(a.accuracy_footprints, u.accuracy_footprints);
  EXPECT_GE(a.completeness[1].fraction, u.completeness[1].fraction - 0.002);
  EXPECT_GE(a.completeness[0].fraction, u.completeness[0].fraction - 0.01);
  EXPECT_TRUE(adaptive.model.closed_manifold);
  EXPECT_LE(adaptive.model.MissedInner(), 10u);
  EXPECT_LE(adaptive.model.CoveredOuter(), 10u);
  EXPECT_EQ(adaptive.hull.main_genus, 1);
  EXPECT_EQ(adaptive.model.main_genus, 1);
  EXPECT_LE(adaptive.model.pieces, 30u);
  // In the concavities the hull cannot reach, too.
  const RegionEvaluation* a_concave = a.Region(kConcaveRegion);
  const RegionEvaluation* u_concave = u.Region(kConcaveRegion);
  ASSERT_TRUE(a_concave && u_concave);
  EXPECT_LE(a_concave->accuracy_footprints, 1.2 * u_concave->accuracy_footprints);
}

// The thesis's fig. 7.9 on the statue: 12 of the 16 ring views see through the window between
// the akimbo arm and the body (the default stills, seed 1). With 8 of them left out the
// visual hull of the other 8 views has the wrong genus (measured 3: the window's cones no
// longer close off the ghosts around it), while the adaptive model, whose cut is not tied to
// the hull's topology, has the object's (1). (The uniform lattice, a shell inside the hull,
// keeps the hull's 3.)
TEST(StereoJobTest, AdaptiveModelHasTheRightGenusWhereTheHullOfFewerViewsHasNot) {
  const std::filesystem::path& input = SixteenViewStills(sim::RigLayout::kRing);
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(input, out.path());
  config.method = StereoMethod::kAdaptive;
  config.leave_out = {"cam00", "cam01", "cam02", "cam06", "cam07", "cam08", "cam09", "cam10"};
  // The premise: each left-out view sees the window as a hole in its silhouette.
  const Eigen::Vector3d window(-0.01, 0.25, 1.2);  // between the left arm and the torso
  for (const CameraModel& camera : LoadCalibration(input / "calibration.yaml")) {
    if (std::find(config.leave_out.begin(), config.leave_out.end(), camera.id) ==
        config.leave_out.end())
      continue;
    const cv::Mat mask =
        cv::imread((input / camera.id / "masks" / "000000.png").string(), cv::IMREAD_GRAYSCALE);
    const std::optional<Eigen::Vector2d> pixel = camera.Project(window);
    ASSERT_TRUE(pixel && !mask.empty()) << camera.id;
    cv::Mat background = mask == 0, parts;
    cv::connectedComponents(background, parts, 4);
    const int window_part = parts.at<int>(cv::Point(static_cast<int>(std::lround(pixel->x())),
                                                    static_cast<int>(std::lround(pixel->y()))));
    EXPECT_NE(window_part, 0) << camera.id << ": the window is not background";
    EXPECT_NE(window_part, parts.at<int>(0, 0)) << camera.id << ": the window is not a hole";
  }
  const StereoJobResult result = RunStereoJob(config, nullptr);
  ASSERT_TRUE(result.success) << result.reason;
  EXPECT_EQ(result.views, 8u);
  ASSERT_TRUE(result.model.evaluation && result.hull.evaluation);
  std::printf(
      "[ stereo job ] 8 views: hull genus %ld (%zu pieces), model genus %ld (%zu pieces); "
      "model %s\n",
      result.hull.main_genus, result.hull.pieces, result.model.main_genus, result.model.pieces,
      result.model.evaluation->Brief().c_str());
  EXPECT_TRUE(result.model.closed_manifold);
  EXPECT_NE(result.hull.main_genus, 1);
  EXPECT_EQ(result.model.main_genus, 1);
  EXPECT_EQ(result.model.MissedInner(), 0u);
  EXPECT_LT(result.model.evaluation->accuracy_footprints,
            result.hull.evaluation->accuracy_footprints);
}

// A dome sees the statue from above too: its hull is tight (0.82 fp) but still fills the
// concavities, where the model is measured 2.0 fp against the hull's 5.7 fp.
TEST(StereoJobTest, SixteenViewDomeMeetsTheAccuracyTargetsAndBeatsTheHullInConcavities) {
  EXPECT_TRUE(CheckedSixteenViews(sim::RigLayout::kDome).success);
}

// A silhouette cut by the image border (as in three Middlebury dino views) does not bound the
// subject: that view is left out of the hull with a warning and the model is still built.
TEST(StereoJobTest, ViewWhoseSilhouetteTouchesTheBorderCarvesTheHullInsideItsImage) {
  silnet::testing::TempDir input;
  std::filesystem::copy(SmallStills(), input.path(), std::filesystem::copy_options::recursive);
  const std::filesystem::path mask_path = input / "cam00" / "masks" / "000000.png";
  cv::Mat mask = cv::imread(mask_path.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(mask.empty());
  cv::Mat rows;
  cv::reduce(mask, rows, 1, cv::REDUCE_MAX);
  int row = 0;
  while (row < rows.rows && rows.at<uint8_t>(row) == 0)
    ++row;
  ASSERT_LT(row, rows.rows);
  mask.row(row).setTo(255);  // the silhouette now reaches both side borders
  ASSERT_TRUE(cv::imwrite(mask_path.string(), mask));

  silnet::testing::TempDir out;
  const StereoJobConfig config = ConfigFor(input.path(), out.path());
  const StereoJobResult result = RunStereoJob(config, nullptr);
  ASSERT_TRUE(result.success) << result.reason;
  const std::string expected =
      "cam00: the silhouette touches the image border; left out of the exact hull, it carves "
      "the hull inside its image";
  EXPECT_NE(std::find(result.warnings.begin(), result.warnings.end(), expected),
            result.warnings.end());
  EXPECT_TRUE(std::filesystem::exists(out / "model.ply"));
  // The model still keeps inside cam00's silhouette, off the added row, which the hull of the
  // other views does not.
  ASSERT_EQ(result.model.views.size(), result.hull.views.size());
  ASSERT_EQ(result.model.views[0].camera_id, "cam00");
  EXPECT_GT(result.hull.views[0].covered_outer, 0u);
  EXPECT_EQ(result.model.views[0].covered_outer, 0u);
  for (const SilhouetteConsistency& view : result.model.views)
    EXPECT_EQ(view.missed_inner, 0u) << view.camera_id;
}

TEST(StereoJobTest, FailureIsDataAndLeavesNoModel) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(input, out.path());
  Progress progress("stereo", 0);
  progress.Cancel();
  const StereoJobResult result = RunStereoJob(config, &progress);
  EXPECT_FALSE(result.success);
  EXPECT_EQ(result.reason, "cancelled");
  EXPECT_FALSE(std::filesystem::exists(out / "model.ply"));
  cv::FileStorage fs((out / "stereo.yaml").string(), cv::FileStorage::READ);
  EXPECT_EQ(static_cast<std::string>(fs["reason"]), "cancelled");
  EXPECT_NE(ReadText(out / "report.html").find("No model: cancelled"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(out / "views"));

  config.graph_cut.lambda = 0;
  EXPECT_THROW(RunStereoJob(config, nullptr), InputError);
}

// The adaptive method reports its mesh's levels to the job's progress and stops when it is
// cancelled within one (the job once ran the whole adaptive stage through a SIGTERM).
TEST(StereoJobTest, AdaptiveMethodStopsWhenCancelledMidJob) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(input, out.path());
  config.method = StereoMethod::kAdaptive;
  Progress* self = nullptr;
  bool adaptive_reported = false;
  Progress progress(
      "stereo", 0,
      [&](const ProgressUpdate& update) {
        if (update.task.rfind("adaptive mesh level 0", 0) != 0) return;
        adaptive_reported = true;
        self->Cancel();
      },
      std::chrono::milliseconds(0));
  self = &progress;
  const StereoJobResult result = RunStereoJob(config, &progress);
  EXPECT_TRUE(adaptive_reported);
  EXPECT_FALSE(result.success);
  EXPECT_EQ(result.reason, "cancelled");
  EXPECT_FALSE(std::filesystem::exists(out / "model.ply"));
}

// --leave-out: the named cameras are not loaded (and said so); a name that is no loaded
// view, or leaving fewer than two views, is an input error.
TEST(StereoJobTest, LeftOutCamerasAreNotUsedAndUnknownOnesAreAnInputError) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir out;
  StereoJobConfig config = ConfigFor(input, out.path());
  config.leave_out = {"cam03", "cam05"};
  Progress progress("stereo", 0);
  progress.Cancel();  // stops right after loading
  const StereoJobResult result = RunStereoJob(config, &progress);
  EXPECT_EQ(result.views, 6u);
  for (const CameraModel& camera : result.cameras)
    EXPECT_TRUE(camera.id != "cam03" && camera.id != "cam05") << camera.id;
  EXPECT_NE(std::find(result.warnings.begin(), result.warnings.end(), "cam05: left out as asked"),
            result.warnings.end());
  config.leave_out = {"cam99"};
  EXPECT_THROW(RunStereoJob(config, nullptr), InputError);
  config.leave_out = {"cam00", "cam01", "cam02", "cam03", "cam04", "cam05", "cam06"};
  EXPECT_THROW(RunStereoJob(config, nullptr), InputError);
}

// Runs `silnet-aggregator stereo INPUT --calib INPUT/calibration.yaml -o WORK/out EXTRA...`
// and returns its exit status (none if it outlived `timeout`) and its stderr.
std::pair<std::optional<int>, std::string> RunStereoCommand(const std::filesystem::path& input,
                                                            const silnet::testing::TempDir& work,
                                                            const std::vector<std::string>& extra,
                                                            std::chrono::seconds timeout) {
  std::vector<std::string> args = {"stereo",  input.string(),
                                   "--calib", (input / "calibration.yaml").string(),
                                   "-o",      (work / "out").string()};
  args.insert(args.end(), extra.begin(), extra.end());
  silnet::testing::ChildProcess cli(
      std::filesystem::path(SILNET_BINARY_DIR) / "aggregator/silnet-aggregator", args, work.path());
  const std::optional<int> status = cli.Wait(timeout);
  return {status, cli.Stderr()};
}

// --lambda and --ballooning set the chosen method's terms; a value out of range for it is an
// input error naming the method's graph cut, before any work.
TEST(StereoCliTest, GraphCutTermsOutOfRangeForTheMethodAreInputErrors) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir work;
  const auto run = [&](const std::vector<std::string>& extra) {
    return RunStereoCommand(input, work, extra, std::chrono::seconds(60));
  };
  const auto [adaptive, adaptive_error] = run({"--method", "adaptive", "--ballooning", "-1"});
  EXPECT_EQ(adaptive, std::optional<int>(2)) << adaptive_error;
  EXPECT_NE(adaptive_error.find("adaptive graph cut"), std::string::npos) << adaptive_error;
  const auto [uniform, uniform_error] = run({"--lambda", "0"});
  EXPECT_EQ(uniform, std::optional<int>(2)) << uniform_error;
  EXPECT_NE(uniform_error.find("graph cut"), std::string::npos) << uniform_error;
  EXPECT_FALSE(std::filesystem::exists(work / "out" / "model.ply"));
}

// --finest-cells sets the adaptive mesh's finest cube side (and its base lattice, 8 times it):
// stereo.yaml states the adaptive method's settings and the finest cells come out that many
// footprints wide. The option is an input error with the uniform method or out of range.
TEST(StereoCliTest, FinestCellsSetTheAdaptiveMeshAndAreInputErrorsOtherwise) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir work;
  const auto run = [&](const std::vector<std::string>& extra) {
    return RunStereoCommand(input, work, extra, std::chrono::seconds(300));
  };
  const auto [uniform, uniform_error] = run({"--finest-cells", "3"});
  EXPECT_EQ(uniform, std::optional<int>(2)) << uniform_error;
  EXPECT_NE(uniform_error.find("--method adaptive"), std::string::npos) << uniform_error;
  const auto [negative, negative_error] = run({"--method", "adaptive", "--finest-cells", "-1"});
  EXPECT_EQ(negative, std::optional<int>(2)) << negative_error;
  EXPECT_NE(negative_error.find("adaptive mesh"), std::string::npos) << negative_error;
  EXPECT_FALSE(std::filesystem::exists(work / "out" / "model.ply"));

  const auto [coarse, coarse_error] = run({"--method", "adaptive", "--finest-cells", "3"});
  ASSERT_EQ(coarse, std::optional<int>(0)) << coarse_error;
  cv::FileStorage fs((work / "out" / "stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["settings"]["finest_cells_footprints"]), 3.0);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["settings"]["base_cells_footprints"]), 24.0);
  EXPECT_DOUBLE_EQ(static_cast<double>(fs["settings"]["ballooning"]),
                   TetGraphCutOptions{}.ballooning);
  const double footprint = static_cast<double>(fs["footprint_mm"]);
  const double finest = static_cast<double>(fs["adaptive"]["finest_spacing_mm"]);
  EXPECT_GT(finest, 2.5 * footprint);
  EXPECT_LE(finest, 3.0 * footprint + 1e-9);
}

// --silhouette-constraints exact cuts with Formulation I's doubled graph (thesis 6.4-6.6):
// stereo.yaml names the method and the colouring's figures; the model is closed and, cut
// inside the hull, covers no outer pixel. The option is an input error with the adaptive
// method.
TEST(StereoCliTest, ExactSilhouetteConstraintsCutTheDoubledGraph) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir work;
  const auto run = [&](const std::vector<std::string>& extra) {
    return RunStereoCommand(input, work, extra, std::chrono::seconds(300));
  };
  const auto [adaptive, adaptive_error] =
      run({"--method", "adaptive", "--silhouette-constraints", "exact"});
  EXPECT_EQ(adaptive, std::optional<int>(2)) << adaptive_error;
  EXPECT_NE(adaptive_error.find("--method uniform"), std::string::npos) << adaptive_error;

  const auto [exact, exact_error] = run({"--silhouette-constraints", "exact"});
  ASSERT_EQ(exact, std::optional<int>(0)) << exact_error;
  cv::FileStorage fs((work / "out" / "stereo.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_NE(static_cast<std::string>(fs["method"]).find("Formulation I"), std::string::npos);
  const cv::FileNode constraints = fs["exact_constraints"];
  EXPECT_GT(static_cast<int>(constraints["segments"]), 0);
  EXPECT_GT(static_cast<int>(constraints["red_cells"]), 0);
  EXPECT_GT(static_cast<int>(constraints["blue_cells"]), 0);
  EXPECT_EQ(static_cast<int>(fs["model"]["covered_outer_pixels"]), 0);
  EXPECT_TRUE(
      CheckClosedManifold(ReadPlyMesh((work / "out" / "model.ply").string())).closed_manifold);
}

TEST(StereoCliTest, MissingCalibrationIsAnInputError) {
  const std::filesystem::path& input = SmallStills();
  silnet::testing::TempDir work;
  silnet::testing::ChildProcess cli(
      std::filesystem::path(SILNET_BINARY_DIR) / "aggregator/silnet-aggregator",
      {"stereo", input.string(), "--calib", (work / "none.yaml").string(), "-o",
       (work / "out").string()},
      work.path());
  EXPECT_EQ(cli.Wait(std::chrono::seconds(60)), std::optional<int>(2)) << cli.Stderr();
  EXPECT_NE(cli.Stderr().find("none.yaml"), std::string::npos) << cli.Stderr();
  EXPECT_FALSE(std::filesystem::exists(work / "out" / "model.ply"));

  // Without --calib the input must be a Middlebury folder; a stills folder is not one.
  silnet::testing::ChildProcess no_calibration(
      std::filesystem::path(SILNET_BINARY_DIR) / "aggregator/silnet-aggregator",
      {"stereo", input.string(), "-o", (work / "out").string()}, work.path());
  EXPECT_EQ(no_calibration.Wait(std::chrono::seconds(60)), std::optional<int>(2))
      << no_calibration.Stderr();
  EXPECT_NE(no_calibration.Stderr().find("no calibration given (--calib)"), std::string::npos)
      << no_calibration.Stderr();
}

}  // namespace
}  // namespace silnet::aggregator
