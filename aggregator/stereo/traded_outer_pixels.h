#pragma once
// Outer pixels a model covers in trade for another view's uncoverable pixel. Where the cameras
// and silhouettes disagree, an inner silhouette pixel of one view may have no point on its ray
// that projects less than the margin outside every other silhouette (uncoverable_pixels.h): a
// model either misses it or covers it with a point that some other view sees outside its
// silhouette. The second kind of pixel is counted here: an outer pixel of view v the model
// covers at a surface point that projects, in another view, onto an inner pixel no consistent
// model covers. Such a pixel is the data's contradiction, not the model's own error; the rest
// of a view's covered outer pixels are.

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/stereo_views.h"
#include "aggregator/stereo/uncoverable_pixels.h"

namespace silnet::aggregator {

// Whether inner silhouette pixels are uncoverable, each pixel's answer computed once.
class UncoverableInnerPixels {
 public:
  // `inner` per view (CV_8UC1, non-zero = inner pixel, the view's size) and the silhouettes
  // grown by the margin (GrowSilhouettes); the views, grown and inner must outlive this.
  UncoverableInnerPixels(const std::vector<StereoView>& views, const GrownSilhouettes& grown,
                         const std::vector<cv::Mat>& inner);

  // True if (x, y) lies in view `v`'s image, is an inner pixel there and is not coverable.
  bool operator()(size_t v, int x, int y);

 private:
  const std::vector<StereoView>& views_;
  const GrownSilhouettes& grown_;
  const std::vector<cv::Mat>& inner_;
  std::vector<cv::Mat> known_;  // per view CV_8UC1: 0 unknown, 1 coverable, 2 uncoverable
};

// How many non-zero pixels of `covered_outer` (CV_8UC1, view `v`'s size: outer pixels of view
// v that `model` covers) the model covers at a surface point projecting, in another view,
// onto an inner pixel that `uncoverable` says no consistent model covers. The point is where
// the pixel centre's ray meets each triangle whose projection covers that centre (the
// triangles RenderMeshSilhouette draws: those with every vertex in front of the camera).
// `projected` holds the model's vertices in view v (ProjectVertices).
size_t CountOuterCoveredForUncoverable(const TriangleMesh& model, const VertexPixels& projected,
                                       const std::vector<StereoView>& views, size_t v,
                                       const cv::Mat& covered_outer,
                                       UncoverableInnerPixels& uncoverable);

}  // namespace silnet::aggregator
