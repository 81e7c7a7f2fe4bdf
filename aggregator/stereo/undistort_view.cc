#include "aggregator/stereo/undistort_view.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {

StereoView UndistortView(const StereoView& view) {
  if (!view.camera.HasDistortion()) return view;
  cv::Mat k, dist;
  cv::eigen2cv(view.camera.K, k);
  cv::eigen2cv(Eigen::Matrix<double, 1, 5>(view.camera.dist.transpose()), dist);
  const cv::Size size(view.camera.width, view.camera.height);
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(k, dist, cv::Mat(), k, size, CV_32FC1, map_x, map_y);
  StereoView out = view;
  cv::remap(view.image, out.image, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  cv::Mat mask;
  cv::remap(view.mask, mask, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  out.mask = mask >= 128;
  out.camera.dist.setZero();
  return out;
}

}  // namespace silnet::aggregator
