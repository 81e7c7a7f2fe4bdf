#pragma once
// Zhang's distance between two fundamental matrices (thesis 2.3.4, ref. 161): how far, in
// pixels, the epipolar lines of one are from points lying on the epipolar lines of the
// other, averaged over points of both images. Unlike the Frobenius norm of the difference
// it measures what matters: whether the two predict the same epipolar lines.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace silnet::aggregator {

// Mean distance in pixels for images of `width` x `height` (both views), over a fixed grid
// of sample points; symmetric in its arguments.
double FundamentalDistance(const Eigen::Matrix3d& f1, const Eigen::Matrix3d& f2, int width,
                           int height);

}  // namespace silnet::aggregator
