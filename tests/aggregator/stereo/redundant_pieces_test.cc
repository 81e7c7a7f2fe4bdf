// Removing the floating pieces a stereo model does not need (aggregator/stereo/
// redundant_pieces.h): a sphere with a piece inside it, a blob above it that the silhouettes
// show, and a second copy of that blob. The inner piece and one copy go; the blob stays; no
// view misses or covers a pixel it did not before.

#include "aggregator/stereo/redundant_pieces.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_topology.h"
#include "aggregator/stereo/model_evaluation.h"
#include "test_spheres.h"

namespace silnet::aggregator {
namespace {

const Eigen::Vector3d kCentre(0.0, 0.0, 1.0);
constexpr double kRadius = 0.1;

// Six ring views of the sphere whose silhouettes are those of `model` exactly.
std::vector<StereoView> ViewsOf(const TriangleMesh& model) {
  std::vector<StereoView> views =
      testing::TexturedSphereViews(kCentre, kRadius, 6, 0.8, 320, 240, 300);
  for (StereoView& view : views)
    view.mask = RenderMeshSilhouette(model, view.camera);
  return views;
}

TEST(RedundantPiecesTest, RemovesThePiecesNoPixelNeedsAndKeepsTheOthers) {
  TriangleMesh model = testing::Icosphere(kCentre, kRadius, 4);
  testing::AppendPiece(testing::Icosphere(kCentre, 0.3 * kRadius, 2),
                       &model);  // inside: hidden everywhere
  const TriangleMesh blob = testing::Icosphere(kCentre + Eigen::Vector3d(0, 0, 0.13), 0.02, 2);
  testing::AppendPiece(blob, &model);
  testing::AppendPiece(blob, &model);  // a copy: either one covers the blob's pixels
  const std::vector<StereoView> views = ViewsOf(model);
  const TriangleMesh before = model;

  const RedundantPieceStats stats = RemoveRedundantPieces(views, &model, kSilhouetteMarginPx, 2);
  EXPECT_EQ(stats.pieces_before, 4u);
  EXPECT_EQ(stats.removed, 2u);
  EXPECT_EQ(stats.triangles_removed, before.triangles.size() - model.triangles.size());
  EXPECT_EQ(MeshComponents(model).size(), 2u);
  EXPECT_TRUE(CheckClosedManifold(model).closed_manifold);
  // The blob's pixels are inner pixels: it must still be there, covering them.
  for (size_t v = 0; v < views.size(); ++v) {
    const cv::Mat inner = InnerSilhouettePixels(views[v].mask, kSilhouetteMarginPx);
    const cv::Mat was = RenderMeshSilhouette(before, views[v].camera);
    const cv::Mat now = RenderMeshSilhouette(model, views[v].camera);
    EXPECT_EQ(cv::countNonZero(inner & was & ~now), 0) << "view " << v << " misses more";
    EXPECT_EQ(cv::countNonZero(now & ~was), 0) << "view " << v << " covers more";
  }
  size_t missed = 0;
  for (const SilhouetteConsistency& c : MeasureSilhouetteConsistency(model, views))
    missed += c.missed_inner;
  EXPECT_EQ(missed, 0u);
}

TEST(RedundantPiecesTest, LeavesAOnePieceMeshAsItIs) {
  TriangleMesh model = testing::Icosphere(kCentre, kRadius, 3);
  const TriangleMesh before = model;
  const RedundantPieceStats stats = RemoveRedundantPieces(ViewsOf(model), &model);
  EXPECT_EQ(stats.pieces_before, 1u);
  EXPECT_EQ(stats.removed, 0u);
  EXPECT_EQ(model.vertices, before.vertices);
  EXPECT_EQ(model.triangles, before.triangles);
}

}  // namespace
}  // namespace silnet::aggregator
