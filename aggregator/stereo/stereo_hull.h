#pragma once
// The visual hull the stereo job cuts its model from: the exact polyhedral hull of the
// silhouettes that lie inside their images, or a voxel hull where the exact one cannot be
// closed.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/stereo/volumetric_graph_cut.h"

namespace silnet::aggregator {

// True if any pixel of the outermost rows or columns of `mask` is silhouette: the subject
// may continue outside the image, so the silhouette does not bound it.
bool TouchesBorder(const cv::Mat& mask);

// The exact polyhedral hull of `views`, or, when it cannot be closed (symmetric rings such
// as the Middlebury temple's; issue 20), the voxel hull carved at one pixel footprint (the
// mean at the centre of the viewing cones' box) on `threads` threads (0 = all), with a
// warning appended to `warnings` and logged. Failure is data, as ComputePolyhedralHull's.
PolyhedralHullResult ComputeStereoHull(const CutSilhouettes& views, int threads,
                                       std::vector<std::string>* warnings);

}  // namespace silnet::aggregator
