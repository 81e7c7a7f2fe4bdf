// The adaptive stereo's photo-consistency (thesis 7.3.2): patches on a textured plane seen by
// a few cameras score high on the plane and low off it; the photo-consistency driven mesh of
// simulated stills refines down to nearly all of the true surface and stays near it.

#include "aggregator/stereo/adaptive_tet_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "aggregator/hulls/nearest_point.h"
#include "aggregator/stereo/adaptive_stereo.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/tet_cell_labels.h"
#include "aggregator/stereo/tet_graph_cut.h"
#include "aggregator/stereo/tet_point_locator.h"
#include "aggregator/stereo/tet_silhouette_step.h"
#include "shared/util/check.h"
#include "tests/aggregator/stereo/simulated_stills.h"
#include "tests/aggregator/stereo/test_spheres.h"

namespace silnet::aggregator {
namespace {

// A pattern on the plane z = 0 (grey levels 0..255), wavelengths of 7-12 pixels in the views.
double Texture(double x, double y) {
  return 128 + 50 * std::sin(190 * x + 30 * y) + 40 * std::sin(170 * y - 90 * x + 1.0) +
         30 * std::sin(230 * x + 200 * y + 2.0);
}

// Six cameras on a circle of radius 1 m at height 1 m looking at the origin, each rendering
// the textured plane z = 0 (the whole image inside the silhouette).
std::vector<StereoView> PlaneViews() {
  std::vector<StereoView> views;
  for (int c = 0; c < 6; ++c) {
    const double angle = 2 * std::numbers::pi * c / 6;
    const Eigen::Vector3d centre(std::cos(angle), std::sin(angle), 1.0);
    StereoView view;
    view.camera.id = "cam" + std::to_string(c);
    view.camera.width = 320;
    view.camera.height = 240;
    view.camera.K << 400, 0, 159.5, 0, 400, 119.5, 0, 0, 1;
    view.camera.R = LookAtRotation(centre, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    view.camera.t = -view.camera.R * centre;
    view.image = cv::Mat(240, 320, CV_8UC3);
    view.mask = cv::Mat(240, 320, CV_8UC1, cv::Scalar(255));
    for (int y = 0; y < 240; ++y) {
      for (int x = 0; x < 320; ++x) {
        const Eigen::Vector3d ray =
            view.camera.R.transpose() * view.camera.PixelRay(Eigen::Vector2d(x, y));
        const double s = -centre.z() / ray.z();
        const Eigen::Vector3d p = centre + s * ray;
        const auto g = static_cast<uint8_t>(std::clamp(Texture(p.x(), p.y()), 0.0, 255.0));
        view.image.at<cv::Vec3b>(y, x) = cv::Vec3b(g, g, g);
      }
    }
    views.push_back(std::move(view));
  }
  return views;
}

TEST(PatchPhotoConsistencyTest, PatchesScoreHighOnATexturedPlaneAndLowOffIt) {
  const std::vector<StereoView> views = PlaneViews();
  const PatchScorer scorer(views, {});
  // The footprint at the origin: 1.41 m away at f = 400 px.
  const double footprint = std::sqrt(2.0) / 400;
  int on = 0, off = 0;
  const int points = 40;
  for (int k = 0; k < points; ++k) {
    const Eigen::Vector3d x(0.05 * std::cos(k * 0.7), 0.05 * std::sin(k * 1.3), 0.0);
    const PatchScore at = scorer.BestPlane(x, footprint);
    EXPECT_GE(at.views, 3);
    if (at.score >= 0.9) ++on;
    const PatchScore above = scorer.BestPlane(x + Eigen::Vector3d(0, 0, 4 * footprint), footprint);
    if (above.score < 0.9) ++off;
  }
  std::printf(
      "[ patches ] on the plane %d of %d score >= 0.9; 4 footprints above, "
      "%d of %d score < 0.9\n",
      on, points, off, points);
  EXPECT_GE(on, points * 9 / 10);
  EXPECT_GE(off, points * 9 / 10);
  // The prefilter changes no score that passes it, nor does scoring in full only the two
  // orientations it ranks best.
  int same = 0;
  for (int k = 0; k < points; ++k) {
    const Eigen::Vector3d x(0.04 * std::cos(k * 0.9), 0.04 * std::sin(k * 1.1), 0.0);
    const float all = scorer.BestPlane(x, footprint).score;
    EXPECT_FLOAT_EQ(scorer.BestPlane(x, footprint, 0.75).score, all);
    same += scorer.BestPlane(x, footprint, 0.75, nullptr, 2).score == all ? 1 : 0;
  }
  EXPECT_EQ(same, points);
}

TEST(PatchPhotoConsistencyTest, EitherSideIsTheBetterOfTheTwoPlanes) {
  const std::vector<StereoView> views = PlaneViews();
  const PatchScorer scorer(views, {});
  const double footprint = std::sqrt(2.0) / 400;
  const Eigen::Vector3d u = Eigen::Vector3d(1, 1, 0).normalized(),
                        v = Eigen::Vector3d(-1, 1, 0).normalized();
  const Eigen::Vector3d n = u.cross(v);
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0.01, 0.02, 0), Eigen::Vector3d(0.03, -0.01, 0.01)}) {
    const float up = scorer.Plane(x, n, u, v, footprint).score;
    const float down = scorer.Plane(x, -n, u, v, footprint).score;
    EXPECT_FLOAT_EQ(scorer.PlaneEitherSide(x, n, u, v, footprint).score, std::max(up, down));
    EXPECT_FLOAT_EQ(scorer.PlaneEitherSide(x, -n, u, v, footprint).score, std::max(up, down));
  }
  // On the plane the side the cameras see scores high in full, whatever the prefilter.
  const Eigen::Vector3d on(0.01, 0.02, 0);
  EXPECT_GE(scorer.PlaneEitherSide(on, n, u, v, footprint, 0.4).score, 0.9f);
}

TEST(PatchPhotoConsistencyTest, PlaneGridScoresAsItsPointsOneByOne) {
  // Plane patches are sampled on their affine image grid; AlongNormal with no shift and no
  // bend projects the same points one by one. The two must agree, on the plane and off it,
  // and where the patch leaves a view's image.
  const std::vector<StereoView> views = PlaneViews();
  const PatchScorer scorer(views, {});
  const double footprint = std::sqrt(2.0) / 400;
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.1, 1).normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  int scored = 0;
  for (int k = 0; k < 30; ++k) {
    const Eigen::Vector3d x(0.3 * std::cos(k * 0.7), 0.3 * std::sin(k * 1.3), 0.01 * (k % 5));
    const float grid = scorer.Plane(x, n, u, v, footprint).score;
    const float points = scorer.AlongNormal(x, n, u, v, footprint, 0.0, {0.0})[0];
    EXPECT_NEAR(grid, points, 1e-5) << "at point " << k;
    scored += grid > -1 ? 1 : 0;
  }
  EXPECT_GE(scored, 10);
}

TEST(PatchPhotoConsistencyTest, OptionsAreValidated) {
  std::string reason;
  PatchOptions options;
  EXPECT_TRUE(options.IsValid(&reason));
  options.mu = 6;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("odd"), std::string::npos);
  AdaptiveTetMeshOptions mesh;
  EXPECT_TRUE(mesh.IsValid(&reason));
  mesh.finest_spacing_footprints = 2 * mesh.base_spacing_footprints;
  EXPECT_FALSE(mesh.IsValid(&reason));
  // Setting the finest cells keeps the defaults' three levels of halving.
  AdaptiveTetMeshOptions coarse;
  coarse.SetFinestSpacing(3);
  EXPECT_DOUBLE_EQ(coarse.finest_spacing_footprints, 3);
  EXPECT_DOUBLE_EQ(coarse.base_spacing_footprints, 24);
  EXPECT_TRUE(coarse.IsValid(&reason));
  coarse.SetFinestSpacing(-1);
  EXPECT_DOUBLE_EQ(coarse.base_spacing_footprints, 24);
  EXPECT_FALSE(coarse.IsValid(&reason));
  EXPECT_NE(reason.find("finest_spacing_footprints"), std::string::npos) << reason;
}

// Simulated stills of the statue (a ring of 16 cameras, 480x360) with the box of their hull.
struct Stills : testing::SimulatedStills {
  WorldBox box;
};

Stills MakeStills() {
  Stills out{testing::MakeSimulatedStills(16, 480, 360, 3), {}};
  for (const Eigen::Vector3f& v : out.hull.vertices)
    out.box.extend(v.cast<double>());
  return out;
}

// The stills and their adaptive mesh, made once for the tests below.
const Stills& Ring16() {
  static const Stills stills = MakeStills();
  return stills;
}

const AdaptiveTetMesh& Ring16Mesh() {
  static const AdaptiveTetMesh mesh = [] {
    AdaptiveTetMeshOptions options;
    options.finest_spacing_footprints = 2.0;  // cells with edges of 1.7-2 px
    return BuildAdaptiveTetMesh(Ring16().views.views, Ring16().box, Ring16().footprint, options);
  }();
  return mesh;
}

TEST(AdaptiveTetMeshTest, RefinesDownToTheTrueSurfaceOfSimulatedStills) {
  const Stills& stills = Ring16();
  const AdaptiveTetMesh& adaptive = Ring16Mesh();
  const RedGreenMesh& mesh = adaptive.mesh;
  ASSERT_EQ(adaptive.levels.size(), 4u);
  const int finest = adaptive.levels.back().level;
  const double spacing = adaptive.levels.back().spacing;

  // The quasi-dense points lie on the surface.
  std::vector<Eigen::Vector3d> points;
  for (const OrientedPoint& p : adaptive.points)
    points.push_back(p.point);
  const NearestPoint truth(stills.truth);
  std::vector<double> error = truth.Distances(points);
  std::sort(error.begin(), error.end());
  ASSERT_GT(points.size(), 1000u);
  const double median = error[error.size() / 2] / stills.footprint;
  const double p90 = error[error.size() * 9 / 10] / stills.footprint;

  // Every part of the true surface lies in cells of the finest level: the nearest finest
  // cell's centroid is within one cube side.
  std::vector<Eigen::Vector3d> centroids;
  for (int32_t leaf : mesh.Leaves()) {
    if (mesh.Level(leaf) != finest) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int32_t v : mesh.Corners(leaf))
      c += mesh.Vertices()[v] / 4;
    centroids.push_back(c);
  }
  const NearestPoint fine(centroids);
  size_t covered = 0;
  for (double d : fine.Distances(stills.truth))
    covered += d <= spacing ? 1 : 0;
  const double coverage = static_cast<double>(covered) / static_cast<double>(stills.truth.size());

  // And the finest cells stay near it.
  std::vector<double> cell_error = truth.Distances(centroids);
  std::sort(cell_error.begin(), cell_error.end());
  const double cell_p90 = cell_error[cell_error.size() * 9 / 10] / stills.footprint;

  const size_t cells = mesh.Conform().mesh.tetrahedra.size();
  const size_t uniform = BuildBccLattice(stills.box, spacing).tetrahedra.size();
  std::printf(
      "[ adaptive mesh ] %zu points: median %.2f fp, 90 %% within %.2f fp; truth in finest cells "
      "%.4f; finest cells within %.2f fp (90 %%); %zu cells, uniform lattice at the finest "
      "spacing %zu\n",
      points.size(), median, p90, coverage, cell_p90, cells, uniform);
  // Measured (2026-11-26): median 1.05 fp, 90 % within 5.1 fp; all of the truth in finest
  // cells (94.8 % by photo-consistency alone, the rest through the hull's surface); cells 90 %
  // within 6.0 fp; 9 times fewer cells than the uniform lattice.
  EXPECT_LE(median, 1.25);
  EXPECT_LE(p90, 6.0);
  EXPECT_GE(coverage, 0.99);
  EXPECT_LE(cell_p90, 7.0);
  EXPECT_LE(cells * 7, uniform);
}

// Labels, the cut on the dual graph and the silhouette step: a surface of the statue that
// explains its silhouettes. (Not yet as accurate as the uniform lattice's, nor manifold
// everywhere: no surface refinement, and the concavities the hull fills stay filled;
// docs/PERFORMANCE.md.)
TEST(AdaptiveTetMeshTest, CutWithSilhouetteStepReconstructsTheStatue) {
  const Stills& stills = Ring16();
  const AdaptiveTetMesh& adaptive = Ring16Mesh();
  const ConformingTetMesh conforming = adaptive.mesh.Conform();
  std::vector<int> levels;
  for (int32_t leaf : conforming.leaf)
    levels.push_back(adaptive.mesh.Level(leaf));
  const double spacing = adaptive.levels.back().spacing;
  const PatchScorer scorer(stills.views.views, {});
  CellLabelOptions label_options;
  label_options.ray_step = spacing / 2;
  label_options.ray_start = 2 * spacing;
  label_options.min_chord = spacing / 4;
  CellLabelStats label_stats;
  std::vector<uint32_t> votes;
  std::vector<CellFace> faces = SortedCellFaces(conforming.mesh);
  const std::vector<CellLabel> labels =
      LabelCells(conforming.mesh, faces, levels, adaptive.levels.back().level, scorer,
                 stills.views.Cameras(), adaptive.points, label_options, &label_stats, &votes);
  ASSERT_EQ(votes.size(), labels.size());
  EXPECT_GT(label_stats.outside_hull, 0u);
  EXPECT_GT(label_stats.interior, 0u);

  TetGraphCut cut(conforming.mesh, std::move(faces), labels, votes, scorer, stills.footprint, {});
  const TetPointLocator locator(conforming.mesh, 2 * spacing);
  TetSilhouetteOptions silhouette_options;
  silhouette_options.ray_step = spacing / 2;
  const TetSilhouetteStats step = EnforceSilhouettesOnTets(&cut, conforming.mesh, labels, locator,
                                                           stills.views.views, silhouette_options);
  const TriangleMesh surface = cut.Surface();
  ModelEvaluationOptions evaluation;
  evaluation.footprint = stills.footprint;
  const ModelEvaluation e = EvaluateModel(surface, stills.truth, stills.normals, evaluation);
  size_t inner = 0, missed = 0;
  for (const SilhouetteConsistency& c : MeasureSilhouetteConsistency(surface, stills.views.views)) {
    inner += c.inner_pixels;
    missed += c.missed_inner;
  }
  std::printf(
      "[ adaptive cut ] %zu cells, %zu forced by the silhouettes; missed %zu -> %zu of %zu "
      "inner pixels; %zu forced out, covered outer pixels %zu -> %zu; %s\n",
      cut.nodes(), step.forced, step.missed.front(), missed, inner, step.forced_out,
      step.covered.front(), step.covered.back(), e.Brief().c_str());
  // Measured (2026-11-26): the first cut keeps little more than the seeds (91 176 pixels
  // missed), the step brings it to 1; accuracy 1.69 fp, 82.7 / 99.7 % within 1 / 2 fp (the
  // visual hull: 1.72 fp, 92.0 / 97.5 %).
  EXPECT_LT(missed * 10000, inner);
  ASSERT_EQ(step.covered.size(), step.missed.size());
  EXPECT_LE(step.covered.back(), step.covered.front());
  EXPECT_LE(e.accuracy_footprints, 2.0);
  EXPECT_GE(e.completeness[1].fraction, 0.98);
}

// Background pixels the cut covers: every interior cell on their rays is made exterior
// (thesis 7.4.2), while the silhouette pixels stay covered. The cut starts as a ball 25 %
// larger than the textured sphere the views see (every free cell ballooning).
TEST(TetSilhouetteStepTest, CellsCoveringBackgroundPixelsAreMadeExterior) {
  const Eigen::Vector3d centre(0, 0, 1);
  const double radius = 0.2;
  const std::vector<StereoView> views =
      testing::TexturedSphereViews(centre, radius, 6, 1.5, 160, 120, 200);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.3);
  const TetMesh mesh = BuildBccLattice(WorldBox(centre - half, centre + half), 0.03);
  std::vector<CellLabel> labels(mesh.tetrahedra.size(), CellLabel::kExterior);
  for (size_t t = 0; t < labels.size(); ++t) {
    const Tetrahedron& q = mesh.tetrahedra[t];
    const Eigen::Vector3d c =
        (mesh.vertices[q[0]] + mesh.vertices[q[1]] + mesh.vertices[q[2]] + mesh.vertices[q[3]]) / 4;
    if ((c - centre).norm() < 1.25 * radius) labels[t] = CellLabel::kFree;
  }
  const PatchScorer scorer(views, {});
  TetGraphCutOptions cut_options;
  cut_options.ballooning = 5;
  TetGraphCut cut(mesh, SortedCellFaces(mesh), labels, {}, scorer, 1.5 / 200, cut_options);
  const TetPointLocator locator(mesh, 0.06);
  TetSilhouetteOptions options;
  options.ray_step = 0.005;
  const TetSilhouetteStats step =
      EnforceSilhouettesOnTets(&cut, mesh, labels, locator, views, options);
  std::printf(
      "[ silhouette step ] covered outer pixels %zu -> %zu, missed inner %zu -> %zu; "
      "%zu cells made exterior, %zu interior\n",
      step.covered.front(), step.covered.back(), step.missed.front(), step.missed.back(),
      step.forced_out, step.forced);
  EXPECT_GT(step.covered.front(), 500u);
  EXPECT_GT(step.forced_out, 0u);
  // Measured: 7992 -> 1284 -> 42 -> 10 -> 2 over the rounds.
  EXPECT_LE(step.covered.back(), 10u);
  EXPECT_EQ(step.missed.front(), 0u);
  EXPECT_LE(step.missed.back(), 5u);
  for (size_t t = 0; t < labels.size(); ++t) {
    if (cut.ForcedSide()[t] == 2) {
      EXPECT_FALSE(cut.Interior()[t]) << t;
    }
  }
}

// On the last level tested a face is scored only until it is crossing: the same faces cross,
// with fewer samples scored, and its lattice is not handed down.
TEST(CrossingFacesTest, FacesOfTheLastLevelStopOnceCrossing) {
  const std::vector<StereoView> views = PlaneViews();
  const PatchScorer scorer(views, {});
  const double footprint = std::sqrt(2.0) / 400;
  CrossingFaceOptions options;
  options.sample_spacing = footprint;
  options.patch_step = footprint;
  // Faces tilted through the textured plane z = 0 (crossing) and faces 10 footprints above
  // or below it.
  std::vector<std::array<int32_t, 3>> ids;
  std::vector<TriangleCorners> corners;
  for (int k = 0; k < 24; ++k) {
    const double angle = 2 * std::numbers::pi * k / 24;
    const Eigen::Vector3d c(0.03 * std::cos(angle), 0.03 * std::sin(angle),
                            (k % 3 - 1) * 10 * footprint);
    corners.push_back({c + Eigen::Vector3d(-0.025, -0.015, -0.008),
                       c + Eigen::Vector3d(0.025, -0.015, 0.008), c + Eigen::Vector3d(0, 0.03, 0)});
    ids.push_back({3 * k, 3 * k + 1, 3 * k + 2});
  }
  CrossingFaces whole(scorer, options), cut_short(scorer, options);
  std::vector<OrientedPoint> points_whole, points_short;
  whole.Sample(ids, corners, &points_whole);
  cut_short.Sample(ids, corners, &points_short, nullptr, false);
  int crossing = 0;
  for (const auto& face : ids) {
    const bool a = whole.Crossing(whole.Counts(face)),
               b = cut_short.Crossing(cut_short.Counts(face));
    EXPECT_EQ(a, b);
    crossing += a ? 1 : 0;
  }
  EXPECT_EQ(crossing, 8);
  EXPECT_LT(cut_short.SamplesScored(), whole.SamplesScored());
  EXPECT_EQ(points_short.size(), points_whole.size());
  cut_short.Inherit(0, 1, 2, 100, 101, 102);
  EXPECT_FALSE(cut_short.Known(SortedFace(0, 100, 102)));
  whole.Inherit(0, 1, 2, 100, 101, 102);
  EXPECT_TRUE(whole.Known(SortedFace(0, 100, 102)));
}

// Cancelled, the long loops inside a stage stop: the crossing test keeps nothing of the call,
// and the dual graph's cut stops before its max-flow, empty, and refuses to be forced.
TEST(AdaptiveStereoTest, CancelledStagesKeepNothingHalfDone) {
  const Eigen::Vector3d centre(0, 0, 1);
  const std::vector<StereoView> views =
      testing::TexturedSphereViews(centre, 0.2, 6, 1.5, 160, 120, 200);
  const PatchScorer scorer(views, {});
  Progress cancelled("stereo", 0);
  cancelled.Cancel();

  CrossingFaceOptions crossing_options;
  crossing_options.sample_spacing = 0.01;
  crossing_options.patch_step = 1.5 / 200;
  CrossingFaces crossing(scorer, crossing_options);
  const std::vector<std::array<int32_t, 3>> ids = {{0, 1, 2}};
  const std::vector<TriangleCorners> corners = {{centre + Eigen::Vector3d(-0.1, -0.1, 0),
                                                 centre + Eigen::Vector3d(0.1, -0.1, 0),
                                                 centre + Eigen::Vector3d(0, 0.1, 0)}};
  std::vector<OrientedPoint> points;
  crossing.Sample(ids, corners, &points, &cancelled);
  EXPECT_FALSE(crossing.Known(ids[0]));
  EXPECT_TRUE(points.empty());
  crossing.Sample(ids, corners, &points);
  EXPECT_TRUE(crossing.Known(ids[0]));
  EXPECT_GT(crossing.Counts(ids[0]).inside, 0);

  const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.3);
  const TetMesh mesh = BuildBccLattice(WorldBox(centre - half, centre + half), 0.03);
  const std::vector<CellLabel> labels(mesh.tetrahedra.size(), CellLabel::kFree);
  TetGraphCut cut(mesh, SortedCellFaces(mesh), labels, {}, scorer, 1.5 / 200, {}, &cancelled);
  EXPECT_TRUE(cut.Cancelled());
  EXPECT_EQ(std::count(cut.Interior().begin(), cut.Interior().end(), 1), 0);
  EXPECT_THROW(cut.ForceInterior({0}), CheckError);
}

TEST(AdaptiveStereoTest, CancellationIsAFailureWithAReason) {
  const Stills& stills = Ring16();
  Progress progress("stereo", 0);
  progress.Cancel();
  const AdaptiveStereoResult result =
      RunAdaptiveStereo(stills.views.views, stills.hull, stills.footprint, {}, &progress);
  EXPECT_FALSE(result.success);
  EXPECT_EQ(result.reason, "cancelled");
}

}  // namespace
}  // namespace silnet::aggregator
