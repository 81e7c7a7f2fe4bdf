// The local surface refinement (thesis 7.4.3) on a textured sphere seen by a ring of cameras:
// normals and curvatures of a sphere mesh, the texture and silhouette forces of spheres too
// large and too small, and the whole refinement bringing such spheres back onto the true one
// while they stay closed, manifold and consistent with the silhouettes.

#include "aggregator/stereo/surface_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/stereo/coverage_restore.h"
#include "aggregator/stereo/model_evaluation.h"
#include "shared/util/check.h"
#include "tests/aggregator/stereo/test_spheres.h"

namespace silnet::aggregator {
namespace {

using testing::Icosphere;
using testing::TexturedSphereViews;

const Eigen::Vector3d kCentre(0.05, -0.1, 1.0);
constexpr double kRadius = 0.25;
constexpr double kDistance = 1.5;
constexpr double kFocal = 500;
constexpr double kFootprint = (kDistance - kRadius) / kFocal;  // at the sphere's front, 2.5 mm

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Distances of the vertices from the true sphere, signed (outside positive).
std::vector<double> RadialErrors(const TriangleMesh& mesh) {
  std::vector<double> errors;
  for (const Eigen::Vector3f& v : mesh.vertices)
    errors.push_back((v.cast<double>() - kCentre).norm() - kRadius);
  return errors;
}

double MeanAbs(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values)
    sum += std::abs(v);
  return sum / static_cast<double>(values.size());
}

const std::vector<StereoView>& Views() {
  static const std::vector<StereoView> views =
      TexturedSphereViews(kCentre, kRadius, 12, kDistance, 480, 360, kFocal);
  return views;
}

TEST(SurfaceForcesTest, SphereNormalsPointOutAndCurvatureIsOneOverTheRadius) {
  const TriangleMesh sphere = Icosphere(kCentre, kRadius, 4);
  const std::vector<Eigen::Vector3d> normals = VertexNormals(sphere);
  for (size_t i = 0; i < sphere.vertices.size(); ++i) {
    const Eigen::Vector3d radial = (sphere.vertices[i].cast<double>() - kCentre).normalized();
    ASSERT_GT(normals[i].dot(radial), 0.999) << "vertex " << i;
  }
  for (int rounds : {0, 3}) {
    const std::vector<double> curvature =
        VertexCurvatures(sphere, FindVertexNeighbours(sphere), normals, rounds);
    EXPECT_NEAR(Median(curvature), 1 / kRadius, 0.03 / kRadius) << rounds << " rounds";
    EXPECT_GT(*std::min_element(curvature.begin(), curvature.end()), 0.8 / kRadius);
  }
  // An inside-out sphere is concave everywhere.
  TriangleMesh inverted = sphere;
  for (auto& t : inverted.triangles)
    std::swap(t[1], t[2]);
  EXPECT_NEAR(Median(VertexCurvatures(inverted, FindVertexNeighbours(inverted),
                                      VertexNormals(inverted), 0)),
              -1 / kRadius, 0.03 / kRadius);
}

// A sphere two footprints too large is pushed in wherever it covers background pixels (nearly
// everywhere: each vertex is near some view's rim); one two footprints too small is pulled
// out on the views' rims only, and its other vertices feel nothing.
TEST(SurfaceForcesTest, SilhouetteForceBringsRimVerticesOntoTheOutlines) {
  const SilhouetteForce force(Views(), {});
  for (double error : {2.0, -2.0}) {
    const TriangleMesh sphere = Icosphere(kCentre, kRadius + error * kFootprint, 5);
    const std::vector<Eigen::Vector3d> normals = VertexNormals(sphere);
    std::vector<double> offsets;
    for (size_t i = 0; i < sphere.vertices.size(); ++i) {
      const NormalOffset f = force.At(sphere.vertices[i].cast<double>(), normals[i]);
      if (f.weight > 0) offsets.push_back(f.offset / kFootprint);
    }
    ASSERT_GT(offsets.size(), 100u);
    const double median = Median(offsets);
    const auto [low, high] = std::minmax_element(offsets.begin(), offsets.end());
    std::printf(
        "[ silhouette force ] sphere %+.0f fp: %zu of %zu vertices moved, offsets %.2f "
        "to %.2f fp, median %.2f fp\n",
        error, offsets.size(), sphere.vertices.size(), *low, *high, median);
    if (error > 0) {
      // Inwards, by about the error less half a pixel (back to the background's centres); the
      // masks' pixels make the outline's distance uncertain by about half a pixel.
      EXPECT_GT(offsets.size(), sphere.vertices.size() * 9 / 10);
      EXPECT_LT(*high, 0.0);
      EXPECT_GT(*low, -error - 0.5);
      EXPECT_LT(median, -0.5);
    } else {
      EXPECT_LT(offsets.size(), sphere.vertices.size() / 2);
      EXPECT_NEAR(median, -error, 0.3);
      EXPECT_GT(*low, 0.0);
      EXPECT_LT(*high, -error + 1.2);
    }
  }
}

TEST(SurfaceForcesTest, TextureForceFindsTheSurfaceAlongTheNormal) {
  const PatchScorer scorer(Views(), {});
  for (double error : {1.2, -1.7}) {
    const TriangleMesh sphere = Icosphere(kCentre, kRadius + error * kFootprint, 4);
    const std::vector<Eigen::Vector3d> normals = VertexNormals(sphere);
    TextureForceOptions options;
    options.range = 3 * kFootprint;
    options.step = 0.5 * kFootprint;
    options.patch_step = kFootprint;
    options.min_score = 0.7;
    const std::vector<NormalOffset> forces = TextureForces(
        sphere, normals, VertexCurvatures(sphere, FindVertexNeighbours(sphere), normals, 2), scorer,
        options, 2);
    std::vector<double> residual;
    for (size_t i = 0; i < forces.size(); ++i)
      if (forces[i].weight > 0) residual.push_back(error + forces[i].offset / kFootprint);
    ASSERT_GT(residual.size(), sphere.vertices.size() / 2);
    std::printf(
        "[ texture force ] sphere %+.1f fp: %zu of %zu vertices scored, residual median "
        "%.2f fp, mean |.| %.2f fp\n",
        error, residual.size(), sphere.vertices.size(), Median(residual), MeanAbs(residual));
    EXPECT_LT(std::abs(Median(residual)), 0.25);
    EXPECT_LT(MeanAbs(residual), 0.5);
  }
}

// The refinement brings spheres 1.5 footprints too large or too small back within a fraction
// of a footprint, remeshing edges longer than 2 px, and the result is closed, manifold and
// explains the silhouettes.
TEST(SurfaceRefinementTest, SpheresTooLargeOrTooSmallComeBackOntoTheTrueSurface) {
  const PatchScorer scorer(Views(), {});
  for (double error : {1.5, -1.5}) {
    const TriangleMesh start = Icosphere(kCentre, kRadius + error * kFootprint, 4);
    SurfaceRefinementOptions options;
    options.threads = 2;
    SurfaceRefinementStats stats;
    const TriangleMesh refined = RefineSurface(start, Views(), scorer, kFootprint, options, &stats);
    const double before = MeanAbs(RadialErrors(start)) / kFootprint;
    const double after = MeanAbs(RadialErrors(refined)) / kFootprint;
    size_t missed = 0, covered = 0;
    for (const SilhouetteConsistency& v : MeasureSilhouetteConsistency(refined, Views())) {
      missed += v.missed_inner;
      covered += v.covered_outer;
    }
    std::printf(
        "[ refinement ] sphere %+.1f fp: mean |error| %.2f -> %.2f fp, %zu -> %zu "
        "vertices, %zu textured, %zu on rims; silhouettes: %zu missed, %zu covered\n",
        error, before, after, stats.vertices_in, stats.vertices, stats.textured, stats.rims, missed,
        covered);
    EXPECT_TRUE(CheckClosedManifold(refined).closed_manifold);
    EXPECT_LT(after, 0.35);
    EXPECT_GT(stats.vertices, stats.vertices_in);  // level-4 edges are ~3 px long
    EXPECT_GT(stats.textured, stats.vertices / 4);
    EXPECT_LT(missed + covered, 50u);
  }
}

// A dent pushed into the sphere uncovers silhouette pixels; putting back the vertices near
// them restores the coverage and leaves the rest of the surface as it was.
TEST(CoverageRestoreTest, VerticesNearUncoveredPixelsGoBackUntilTheyAreCovered) {
  const TriangleMesh sphere = Icosphere(kCentre, kRadius, 5);
  const std::vector<cv::Mat> covered = CoveredInnerPixels(sphere, Views());
  TriangleMesh dented = sphere;
  const Eigen::Vector3d towards = Eigen::Vector3d(1, 1, 0.3).normalized();
  size_t moved = 0;
  for (Eigen::Vector3f& v : dented.vertices) {
    const Eigen::Vector3d radial = (v.cast<double>() - kCentre) / kRadius;
    if (radial.dot(towards) < 0.9) continue;
    v = (kCentre + (kRadius - 4 * kFootprint) * radial).cast<float>();
    ++moved;
  }
  size_t uncovered = 0;
  for (const SilhouetteConsistency& v : MeasureSilhouetteConsistency(dented, Views()))
    uncovered += v.missed_inner;
  ASSERT_GT(uncovered, 20u);
  const CoverageRestoreStats stats = RestoreCoverage(Views(), covered, sphere.vertices, 6, &dented);
  size_t back = 0;
  for (size_t i = 0; i < dented.vertices.size(); ++i)
    back += dented.vertices[i] == sphere.vertices[i];
  std::printf(
      "[ coverage ] %zu vertices dented, %zu pixels uncovered; %zu rounds put back %zu, "
      "%zu still dented, %zu pixels left\n",
      moved, uncovered, stats.rounds, stats.restored, dented.vertices.size() - back,
      stats.still_uncovered);
  EXPECT_EQ(stats.still_uncovered, 0u);
  size_t missed = 0;
  for (const SilhouetteConsistency& v : MeasureSilhouetteConsistency(dented, Views()))
    missed += v.missed_inner;
  EXPECT_EQ(missed, 0u);
  EXPECT_GT(stats.restored, 0u);
  EXPECT_LE(stats.restored, moved);
  // The dent's middle, seen face on by no view's rim, may stay.
  EXPECT_GT(dented.vertices.size() - back, 0u);
}

TEST(SurfaceRefinementTest, ZeroIterationsReturnTheSurfaceAndBadOptionsAreRejected) {
  const PatchScorer scorer(Views(), {});
  const TriangleMesh sphere = Icosphere(kCentre, kRadius, 3);
  SurfaceRefinementOptions none;
  none.iterations = 0;
  const TriangleMesh same = RefineSurface(sphere, Views(), scorer, kFootprint, none);
  EXPECT_EQ(same.triangles, sphere.triangles);
  EXPECT_EQ(same.vertices, sphere.vertices);
  SurfaceRefinementOptions bad;
  std::string reason;
  bad.texture_rate = 0;
  EXPECT_FALSE(bad.IsValid(&reason));
  EXPECT_NE(reason.find("texture_rate"), std::string::npos);
  EXPECT_THROW(RefineSurface(sphere, Views(), scorer, kFootprint, bad), CheckError);
}

}  // namespace
}  // namespace silnet::aggregator
