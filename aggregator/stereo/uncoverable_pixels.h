#pragma once
// Silhouette pixels that no model consistent with the other views can cover. A model that
// covers pixel p of view v has a surface point on p's viewing ray, and that point projects
// into every other view, where a consistent model covers only pixels less than the margin
// outside the silhouette (model_evaluation.h). So if no point of the ray projects into every
// other view's silhouette grown by the margin, the cameras and the silhouettes disagree at p
// and any consistent model misses it; real photographs with given cameras have such pixels
// (a camera 1-2 px off, a shadow thresholded as background), and they separate what a model
// cannot explain from what it fails to.
//
// The ray is clipped to where it lies in front of every other camera and inside the image of
// every view whose silhouette the image border does not cut (outside such an image the point
// is background); beyond the image of a view the border cuts the view says nothing. Along the
// ray each view's grown silhouette is sampled at most half a pixel apart in that view, and
// the ray's stretches inside it intersected view by view: a stretch is widened by half a
// sample, so a thin reach is never missed (a pixel at the limit counts as coverable).

#include <Eigen/Core>
#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <utility>
#include <vector>

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// The views as the coverability test reads them: per view, the pixels whose centres lie less
// than `margin_px` outside the outline (CV_8UC1, 255), whether the image border cuts the
// silhouette, and the camera's projection matrix.
struct GrownSilhouettes {
  std::vector<cv::Mat> grown;
  std::vector<bool> border_cut;
  std::vector<Matrix34d> projections;
};

// Grows every view's mask by `margin_px` (>= 0; the outline runs half a pixel beyond the
// outermost silhouette pixel centres, as InnerSilhouettePixels has it).
GrownSilhouettes GrowSilhouettes(const std::vector<StereoView>& views, double margin_px);

// The part of a pixel's viewing ray inside every other view's grown silhouette: the points
// origin + t * direction (unit) for t in one of the stretches.
struct RayReach {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  std::vector<std::pair<double, double>> stretches;  // sorted, disjoint; the last may be endless

  // The point of the stretches nearest `x`.
  Eigen::Vector3d NearestPoint(const Eigen::Vector3d& x) const;
};

// The reach of the viewing ray through `pixel` of view `v` (pinhole cameras); its stretches
// are empty when the pixel is not coverable. With no other view whose image bounds the ray,
// the whole ray in front of every other camera.
RayReach CoverableReach(const std::vector<StereoView>& views, const GrownSilhouettes& grown,
                        size_t v, const Eigen::Vector2d& pixel);

// True if the viewing ray of pixel (x, y) of view `v` (pinhole cameras) has a point inside
// every other view's grown silhouette. With no other view whose image bounds the ray, true.
bool PixelCoverable(const std::vector<StereoView>& views, const GrownSilhouettes& grown, size_t v,
                    int x, int y);

// How many non-zero pixels of `pixels` (CV_8UC1, view `v`'s size) are not coverable.
size_t CountUncoverable(const std::vector<StereoView>& views, const GrownSilhouettes& grown,
                        size_t v, const cv::Mat& pixels);

}  // namespace silnet::aggregator
