#include "aggregator/calibration/relative_pose.h"

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "aggregator/calibration/essential_refinement.h"

namespace silnet::aggregator {

// The relative pose of link (a -> b) from its essential matrix and correspondences.
std::optional<RelativePose> PoseOfLink(const ViewGraph& graph,
                                       const std::vector<CameraModel>& cameras, size_t a,
                                       size_t b) {
  const ViewLink* link = graph.Find(a, b);
  if (link == nullptr || link->matches.size() < 8) return std::nullopt;
  const CameraModel& ci = cameras[link->i];
  const CameraModel& cj = cameras[link->j];
  const Eigen::Matrix3d e = cj.K.transpose() * link->F * ci.K;
  std::vector<cv::Point2d> xi, xj;
  for (const Correspondence& c : link->matches) {
    const Eigen::Vector3d ri = ci.PixelRay(c.x_i), rj = cj.PixelRay(c.x_j);
    xi.emplace_back(ri.x(), ri.y());
    xj.emplace_back(rj.x(), rj.y());
  }
  cv::Mat e_cv, r_cv, t_cv, mask;
  cv::eigen2cv(e, e_cv);
  const int in_front = cv::recoverPose(e_cv, xi, xj, cv::Mat::eye(3, 3, CV_64F), r_cv, t_cv, mask);
  if (in_front < static_cast<int>(xi.size() / 2)) return std::nullopt;
  RelativePose pose;  // x_j = R x_i + t
  cv::cv2eigen(r_cv, pose.R);
  Eigen::Vector3d t;
  cv::cv2eigen(t_cv, t);
  pose.t = t.normalized();
  pose = RefineRelativePose(ci, cj, link->matches, pose);
  if (link->i == a) return pose;
  return RelativePose{pose.R.transpose(), -pose.R.transpose() * pose.t};
}

// The rotation nearest (Frobenius) to the mean of rotations.
Eigen::Matrix3d ChordalMean(const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& r : rotations)
    sum += r;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// World direction from placed camera p towards camera k, from their relative pose.
Eigen::Vector3d RayTowards(const CameraModel& p, const RelativePose& p_to_k) {
  return (p.R.transpose() * (-p_to_k.R.transpose() * p_to_k.t)).normalized();
}

// The point nearest to the rays c + s d (least squares).
Eigen::Vector3d NearestToRays(const std::vector<Eigen::Vector3d>& origins,
                              const std::vector<Eigen::Vector3d>& directions) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t r = 0; r < origins.size(); ++r) {
    const Eigen::Matrix3d m =
        Eigen::Matrix3d::Identity() - directions[r] * directions[r].transpose();
    a += m;
    b += m * origins[r];
  }
  return a.ldlt().solve(b);
}

}  // namespace silnet::aggregator
