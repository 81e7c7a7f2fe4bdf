#include "aggregator/calibration/known_intrinsics.h"

#include <fmt/format.h>

#include <map>
#include <numbers>
#include <optional>

#include "aggregator/calibration/addition_order.h"
#include "aggregator/calibration/relative_pose.h"
#include "shared/util/log.h"

namespace silnet::aggregator {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

class Chainer {
 public:
  Chainer(const ViewGraph& graph, const std::vector<CameraModel>& cameras,
          const KnownIntrinsicsOptions& options)
      : graph_(graph), options_(options), n_(graph.cameras()) {
    chain_.scene.present.assign(n_, false);
    chain_.scene.cameras = cameras;
    chain_.added_by.assign(n_, "");
    chain_.reasons.assign(n_, "");
  }

  PoseChain Run(Progress* progress) {
    if (progress) progress->Restart("placing cameras (known intrinsics)", n_);
    if (!PlaceFirstPair()) {
      for (size_t k = 0; k < n_; ++k)
        chain_.reasons[k] =
            "no trusted link gives a relative pose with the frontier points in "
            "front of both cameras";
      return std::move(chain_);
    }
    if (progress) progress->Advance(2);
    std::vector<bool> given_up(n_, false);
    const double min_angle = options_.min_ray_angle_deg * kDegree;
    while (!(progress && progress->cancelled())) {
      const auto next =
          NextAddition(graph_, chain_.scene.present, given_up, [&](size_t k, size_t p, size_t q) {
            const auto rp = Pose(p, k), rq = Pose(q, k);
            if (!rp || !rq) return false;
            const double cos = RayTowards(Camera(p), *rp).dot(RayTowards(Camera(q), *rq));
            return std::acos(std::clamp(cos, -1.0, 1.0)) >= min_angle;
          });
      if (!next) break;
      if (Add(*next)) {
        if (progress) progress->Advance();
      } else {
        given_up[next->camera] = true;
      }
    }
    for (size_t k = 0; k < n_; ++k) {
      if (!chain_.scene.present[k] && chain_.reasons[k].empty())
        chain_.reasons[k] = ReasonNotPlaced(graph_, chain_.scene.present, k);
    }
    return std::move(chain_);
  }

 private:
  CameraModel& Camera(size_t c) { return chain_.scene.cameras[c]; }

  std::optional<RelativePose> Pose(size_t a, size_t b) {
    const auto key = std::pair{a, b};
    auto it = poses_.find(key);
    if (it == poses_.end())
      it = poses_.emplace(key, PoseOfLink(graph_, chain_.scene.cameras, a, b)).first;
    return it->second;
  }

  bool PlaceFirstPair() {
    std::vector<const ViewLink*> links;
    for (const ViewLink& l : graph_.links())
      links.push_back(&l);
    std::sort(links.begin(), links.end(),
              [](const ViewLink* a, const ViewLink* b) { return a->spread > b->spread; });
    for (const ViewLink* l : links) {
      const auto pose = Pose(l->i, l->j);
      if (!pose) continue;
      Camera(l->i).R.setIdentity();
      Camera(l->i).t.setZero();
      Camera(l->j).R = pose->R;
      Camera(l->j).t = pose->t;
      chain_.scene.present[l->i] = chain_.scene.present[l->j] = true;
      chain_.added_by[l->i] = chain_.added_by[l->j] = "initial pair";
      Adjust();
      return true;
    }
    return false;
  }

  bool Add(const Addition& a) {
    const size_t k = a.camera;
    std::vector<Eigen::Matrix3d> rotations;
    std::vector<Eigen::Vector3d> origins, directions;
    for (size_t p : {a.first, a.second}) {
      const RelativePose rel = *Pose(p, k);
      rotations.push_back(rel.R * Camera(p).R);
      origins.push_back(Camera(p).Center());
      directions.push_back(RayTowards(Camera(p), rel));
    }
    const Eigen::Vector3d centre = NearestToRays(origins, directions);
    const MetricScene before = chain_.scene;
    const BundleSummary before_bundle = chain_.last_bundle;
    Camera(k).R = ChordalMean(rotations);
    Camera(k).t = -Camera(k).R * centre;
    chain_.scene.present[k] = true;
    Adjust();
    const double rms = CameraRms(k);
    const std::string p = Camera(a.first).id, q = Camera(a.second).id;
    spdlog::debug("known intrinsics: + {} via {} {}: {:.3f} px (camera {:.3f} px)", Camera(k).id, p,
                  q, chain_.last_bundle.rms_px, rms);
    if (!chain_.last_bundle.usable || !(rms <= options_.max_added_rms_px)) {
      chain_.scene = before;
      chain_.last_bundle = before_bundle;
      chain_.reasons[k] = fmt::format(
          "it does not fit the network: reprojection error {:.1f} px after adding it through {} "
          "and {}",
          rms, p, q);
      return false;
    }
    chain_.added_by[k] = "linked to " + p + " and " + q;
    return true;
  }

  void Adjust() {
    MetricScene& s = chain_.scene;
    s.tracks = CollectTracks(graph_, s.present, options_.tracks_per_link);
    s.Triangulate();
    IntrinsicsModel fixed;
    fixed.fixed = true;
    chain_.last_bundle = AdjustEuclidean(&s, fixed, options_.bundle, options_.max_added_rms_px);
  }

  double CameraRms(size_t k) const {
    const MetricScene& s = chain_.scene;
    double sum = 0.0;
    size_t n = 0;
    for (size_t t = 0; t < s.tracks.size(); ++t) {
      for (int view = 0; view < 2; ++view) {
        if ((view == 0 ? s.tracks[t].camera_a : s.tracks[t].camera_b) != k) continue;
        const double e = s.ViewError(t, view);
        sum += e * e;
        ++n;
      }
    }
    return n == 0 ? 1e9 : std::sqrt(sum / static_cast<double>(n));
  }

  const ViewGraph& graph_;
  const KnownIntrinsicsOptions& options_;
  size_t n_;
  PoseChain chain_;
  std::map<std::pair<size_t, size_t>, std::optional<RelativePose>> poses_;
};

}  // namespace

PoseChain ChainKnownIntrinsics(const ViewGraph& graph, const std::vector<CameraModel>& cameras,
                               const KnownIntrinsicsOptions& options, Progress* progress) {
  return Chainer(graph, cameras, options).Run(progress);
}

}  // namespace silnet::aggregator
