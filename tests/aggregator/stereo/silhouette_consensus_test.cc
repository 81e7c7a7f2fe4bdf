// Weak silhouette evidence kept where the other views' hull supports it.

#include "aggregator/stereo/silhouette_consensus.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

constexpr double kRadius = 0.1;  // a sphere at the origin
constexpr uint8_t kWeak = 64;

// View `k` of `n` on a ring of 1 m around the sphere, 160x120 px, focal 300 px, its mask the
// sphere's exact silhouette.
StereoView RingView(int k, int n) {
  StereoView view;
  CameraModel& c = view.camera;
  c.id = "cam" + std::to_string(k);
  c.width = 160;
  c.height = 120;
  c.K << 300, 0, 79.5, 0, 300, 59.5, 0, 0, 1;
  const double a = 2 * M_PI * k / n;
  const Eigen::Vector3d centre(std::cos(a), std::sin(a), 0.2);
  c.R = LookAtRotation(centre, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  c.t = -c.R * centre;
  view.image = cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(128));
  view.mask = cv::Mat::zeros(120, 160, CV_8UC1);
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const Eigen::Vector3d d = (c.R.transpose() * c.PixelRay({double(x), double(y)})).normalized();
      const Eigen::Vector3d o = c.Center();
      if ((o - o.dot(d) * d).norm() < kRadius) view.mask.at<uint8_t>(y, x) = 255;
    }
  }
  return view;
}

// View 0's outline lost to the background and marked weak, and a weak blob away from the
// sphere: the other views confirm the outline and not the blob.
TEST(SilhouetteConsensus, KeepsWeakPixelsTheOtherViewsSupportAndDropsTheRest) {
  std::vector<StereoView> views;
  for (int k = 0; k < 4; ++k)
    views.push_back(RingView(k, 4));
  const cv::Mat exact = views[0].mask.clone();
  cv::Mat inner;
  cv::erode(exact, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
  const cv::Mat rim = exact & ~inner;
  views[0].mask = inner.clone();
  views[0].mask.setTo(kWeak, rim);
  const cv::Rect blob(5, 5, 10, 10);
  views[0].mask(blob).setTo(kWeak);

  std::vector<StereoView> pair(views.begin(), views.begin() + 2);
  const SilhouetteConsensus consensus = ResolveWeakSilhouettes(&views, kWeak);
  EXPECT_EQ(consensus.candidates, static_cast<size_t>(cv::countNonZero(rim) + blob.area()));
  // The rim's pixels whose rays graze the sphere within a pixel may miss the sampled hull.
  EXPECT_GE(cv::countNonZero(views[0].mask & rim), 0.9 * cv::countNonZero(rim));
  EXPECT_EQ(cv::countNonZero(views[0].mask(blob)), 0);
  EXPECT_EQ(cv::countNonZero((views[0].mask != 0) & (views[0].mask != 255)), 0);
  for (size_t v = 1; v < views.size(); ++v)
    EXPECT_EQ(cv::norm(views[v].mask, RingView(static_cast<int>(v), 4).mask, cv::NORM_INF), 0);

  // Two views cannot confirm anything: weak pixels are dropped.
  const SilhouetteConsensus alone = ResolveWeakSilhouettes(&pair, kWeak);
  EXPECT_EQ(alone.kept, 0u);
  EXPECT_EQ(cv::countNonZero(pair[0].mask), cv::countNonZero(inner));
}

// A thin part faint in several views (a dark pole against a dark wall): the sphere's upper cap
// weak in views 0 and 1 alike. Each view's cap is confirmed by the other's weak pixels
// together with the silhouettes of views 2 and 3.
TEST(SilhouetteConsensus, WeakPixelsOfSeveralViewsConfirmEachOther) {
  std::vector<StereoView> views;
  for (int k = 0; k < 4; ++k)
    views.push_back(RingView(k, 4));
  std::vector<cv::Mat> caps;
  for (int v = 0; v < 2; ++v) {
    cv::Mat cap = views[v].mask.clone();
    cap(cv::Rect(0, 45, 160, 75)).setTo(0);  // rows above 45: the top of the sphere's disc
    ASSERT_GT(cv::countNonZero(cap), 100);
    views[v].mask.setTo(kWeak, cap);
    caps.push_back(cap);
  }
  const SilhouetteConsensus consensus = ResolveWeakSilhouettes(&views, kWeak);
  EXPECT_EQ(consensus.candidates,
            static_cast<size_t>(cv::countNonZero(caps[0]) + cv::countNonZero(caps[1])));
  for (int v = 0; v < 2; ++v)
    EXPECT_GE(cv::countNonZero(views[v].mask & caps[v]), 0.9 * cv::countNonZero(caps[v])) << v;
}

}  // namespace
}  // namespace silnet::aggregator
