#include "aggregator/stereo/silhouette_consensus.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

// The point nearest (least squares) to the rays through the centroids of the silhouettes, and
// the radius of a sphere about it holding every silhouette's cone near it.
std::pair<Eigen::Vector3d, double> SubjectSphere(const std::vector<StereoView>& views) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const StereoView& view : views) {
    const cv::Moments m = cv::moments(view.mask == 255, true);
    if (!(m.m00 > 0)) continue;
    const Eigen::Vector3d d =
        (view.camera.R.transpose() * view.camera.PixelRay({m.m10 / m.m00, m.m01 / m.m00}))
            .normalized();
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += p;
    b += p * view.camera.Center();
  }
  const Eigen::Vector3d centre = a.ldlt().solve(b);
  double radius = 0.0;
  for (const StereoView& view : views) {
    const cv::Rect box = cv::boundingRect(view.mask == 255);
    const double distance = (view.camera.Center() - centre).norm();
    radius = std::max(
        radius, 1.5 * 0.5 * std::hypot(box.width, box.height) / view.camera.K(0, 0) * distance);
  }
  return {centre, radius};
}

// True if the ray of pixel (x, y) of view `v` meets the visual hull of the other views'
// silhouettes with their weak pixels (value `weak`).
bool OthersSupport(const std::vector<StereoView>& views, size_t v, int x, int y,
                   const Eigen::Vector3d& centre, double radius, uint8_t weak) {
  const CameraModel& camera = views[v].camera;
  const Eigen::Vector3d origin = camera.Center();
  const Eigen::Vector3d direction =
      (camera.R.transpose() * camera.PixelRay({static_cast<double>(x), static_cast<double>(y)}))
          .normalized();
  const double along = direction.dot(centre - origin);
  const double miss = (origin + along * direction - centre).norm();
  if (miss >= radius) return false;
  const double half = std::sqrt(radius * radius - miss * miss);
  const double step = radius / 500.0;
  for (double t = std::max(0.0, along - half); t <= along + half; t += step) {
    const Eigen::Vector3d point = origin + t * direction;
    bool inside_all = true;
    for (size_t o = 0; o < views.size() && inside_all; ++o) {
      if (o == v) continue;
      const auto pixel = views[o].camera.Project(point);
      if (!pixel) {
        inside_all = false;
        break;
      }
      const int u = static_cast<int>(std::lround(pixel->x()));
      const int w = static_cast<int>(std::lround(pixel->y()));
      const cv::Mat& mask = views[o].mask;
      if (u < 0 || w < 0 || u >= mask.cols || w >= mask.rows) {
        inside_all = false;
        break;
      }
      const uint8_t value = mask.at<uint8_t>(w, u);
      inside_all = value == 255 || value == weak;
    }
    if (inside_all) return true;
  }
  return false;
}

}  // namespace

SilhouetteConsensus ResolveWeakSilhouettes(std::vector<StereoView>* views, uint8_t weak) {
  SilhouetteConsensus result;
  const bool enough = views->size() >= 3;
  const auto [centre, radius] =
      enough ? SubjectSphere(*views) : std::pair{Eigen::Vector3d(Eigen::Vector3d::Zero()), 0.0};
  // Decide on the masks as they came (255 only), then apply.
  std::vector<cv::Mat> resolved(views->size());
  for (size_t v = 0; v < views->size(); ++v) {
    const cv::Mat& mask = (*views)[v].mask;
    resolved[v] = mask == 255;
    for (int y = 0; y < mask.rows; ++y) {
      const uint8_t* in = mask.ptr<uint8_t>(y);
      uint8_t* out = resolved[v].ptr<uint8_t>(y);
      for (int x = 0; x < mask.cols; ++x) {
        if (in[x] != weak) continue;
        ++result.candidates;
        if (enough && OthersSupport(*views, v, x, y, centre, radius, weak)) {
          out[x] = 255;
          ++result.kept;
        }
      }
    }
  }
  for (size_t v = 0; v < views->size(); ++v)
    (*views)[v].mask = resolved[v];
  return result;
}

}  // namespace silnet::aggregator
