#include "aggregator/calibration/projective_reconstruction.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "aggregator/calibration/addition_order.h"
#include "aggregator/calibration/projective_geometry.h"
#include "aggregator/calibration/projective_triplet.h"
#include "shared/util/log.h"

namespace silnet::aggregator {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The view graph's fundamental matrices and correspondences in normalised coordinates.
class NormalisedGraph {
 public:
  NormalisedGraph(const ViewGraph& graph, const std::vector<Eigen::Matrix3d>& normalization)
      : graph_(graph), n_(normalization) {}

  // x_b^T F x_a = 0 in normalised coordinates.
  Eigen::Matrix3d F(size_t a, size_t b) const {
    return n_[b].inverse().transpose() * graph_.FundamentalFromTo(a, b) * n_[a].inverse();
  }
  // The correspondences of link a-b oriented from a to b, normalised.
  std::vector<Correspondence> Matches(size_t a, size_t b) const {
    const ViewLink* link = graph_.Find(a, b);
    std::vector<Correspondence> out;
    if (link == nullptr) return out;
    out.reserve(link->matches.size());
    for (const Correspondence& c : link->matches) {
      const Eigen::Vector2d x_i = (n_[link->i] * c.x_i.homogeneous()).hnormalized();
      const Eigen::Vector2d x_j = (n_[link->j] * c.x_j.homogeneous()).hnormalized();
      out.push_back(link->i == a ? Correspondence{x_i, x_j, c.frame_i}
                                 : Correspondence{x_j, x_i, c.frame_i});
    }
    return out;
  }
  const ViewGraph& graph() const { return graph_; }

 private:
  const ViewGraph& graph_;
  const std::vector<Eigen::Matrix3d>& n_;
};

// The first triplet: all three links present, epipoles apart, the largest total spread.
// Returns cameras ordered so that link 2-3 is the weakest.
std::optional<std::array<size_t, 3>> BestTriplet(const NormalisedGraph& g, double min_angle) {
  const ViewGraph& graph = g.graph();
  std::optional<std::array<size_t, 3>> best;
  double best_score = -1.0;
  for (size_t a = 0; a < graph.cameras(); ++a) {
    for (size_t b = a + 1; b < graph.cameras(); ++b) {
      if (!graph.Find(a, b)) continue;
      for (size_t c = b + 1; c < graph.cameras(); ++c) {
        if (!graph.Find(a, c) || !graph.Find(b, c)) continue;
        const double score = graph.Spread(a, b) + graph.Spread(a, c) + graph.Spread(b, c);
        if (score <= best_score) continue;
        if (TripletEpipoleAngle(g.F(a, b), g.F(a, c), g.F(b, c)) < min_angle) continue;
        // Camera 1 is the one opposite the weakest link.
        std::array<size_t, 3> order{a, b, c};
        const double s_ab = graph.Spread(a, b), s_ac = graph.Spread(a, c),
                     s_bc = graph.Spread(b, c);
        if (s_ab <= s_ac && s_ab <= s_bc) order = {c, a, b};
        if (s_ac < s_ab && s_ac <= s_bc) order = {b, a, c};
        best = order;
        best_score = score;
      }
    }
  }
  return best;
}

// RMS reprojection error of camera k's observations.
double CameraRms(const ProjectiveScene& scene, size_t k) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t t = 0; t < scene.tracks.size(); ++t) {
    if (scene.tracks[t].camera_a != k && scene.tracks[t].camera_b != k) continue;
    const double e = scene.TrackError(t);
    sum += e * e;
    ++n;
  }
  return n == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(n));
}

}  // namespace

size_t ProjectiveReconstruction::placed() const {
  return static_cast<size_t>(std::count(scene.present.begin(), scene.present.end(), true));
}

ProjectiveReconstruction ReconstructProjective(const ViewGraph& graph,
                                               const std::vector<CameraModel>& cameras,
                                               const ProjectiveOptions& options,
                                               Progress* progress) {
  const size_t n = graph.cameras();
  ProjectiveReconstruction out;
  ProjectiveScene& scene = out.scene;
  scene.present.assign(n, false);
  scene.cameras.assign(n, Matrix34d::Zero());
  for (const CameraModel& c : cameras)
    scene.normalization.push_back(ImageNormalization(c.width, c.height));
  out.added_by.assign(n, "");
  out.reasons.assign(n, "");
  const NormalisedGraph g(graph, scene.normalization);
  const double min_angle = options.min_epipole_angle_deg * kDegree;
  if (progress) progress->Restart("projective reconstruction", n);

  const auto adjust = [&] {
    scene.tracks = CollectTracks(graph, scene.present, options.tracks_per_link);
    scene.points.clear();
    out.last_bundle = AdjustProjective(&scene, options.bundle);
  };

  const auto first = BestTriplet(g, min_angle);
  if (!first) {
    for (size_t k = 0; k < n; ++k)
      out.reasons[k] =
          "no three cameras are linked to each other by trusted, non-degenerate "
          "epipolar geometry";
    return out;
  }
  const auto [c1, c2, c3] = *first;
  std::string why;
  const auto triplet =
      ResolveTriplet({g.F(c1, c2), g.F(c1, c3), g.F(c2, c3), g.Matches(c2, c3)}, &why);
  if (!triplet) {
    for (size_t k = 0; k < n; ++k)
      out.reasons[k] = "the initial triplet could not be resolved: " + why;
    return out;
  }
  scene.cameras[c1] = triplet->p1;
  scene.cameras[c2] = triplet->p2;
  scene.cameras[c3] = triplet->p3;
  for (size_t c : {c1, c2, c3}) {
    scene.present[c] = true;
    out.added_by[c] = "initial triplet";
  }
  adjust();
  spdlog::debug("projective: triplet {} {} {}: {:.3f} px", cameras[c1].id, cameras[c2].id,
                cameras[c3].id, out.last_bundle.rms_px);
  if (progress) progress->Advance(3);

  std::vector<bool> given_up(n, false);
  while (!(progress && progress->cancelled())) {
    const auto next =
        NextAddition(graph, scene.present, given_up, [&](size_t k, size_t p, size_t q) {
          const Eigen::Matrix3d f_pq =
              FundamentalFromProjections(scene.cameras[p], scene.cameras[q]);
          return TripletEpipoleAngle(f_pq, g.F(p, k), g.F(q, k)) >= min_angle;
        });
    if (!next) break;
    const size_t k = next->camera, p = next->first, q = next->second;
    const Eigen::Matrix3d f_pq = FundamentalFromProjections(scene.cameras[p], scene.cameras[q]);
    const auto local = ResolveTriplet({f_pq, g.F(p, k), g.F(q, k), g.Matches(q, k)}, &why);
    if (!local) {
      given_up[k] = true;
      out.reasons[k] = "its triplet with " + cameras[p].id + " and " + cameras[q].id +
                       " could not be resolved: " + why;
      continue;
    }
    const Eigen::Matrix4d h =
        AlignProjectiveFrames(local->p1, local->p2, scene.cameras[p], scene.cameras[q]);
    scene.cameras[k] = local->p3 * h;
    const ProjectiveScene before = scene;
    const BundleSummary before_bundle = out.last_bundle;
    scene.present[k] = true;
    adjust();
    const double rms = CameraRms(scene, k);
    spdlog::debug("projective: + {} via {} {}: {:.3f} px (camera {:.3f} px)", cameras[k].id,
                  cameras[p].id, cameras[q].id, out.last_bundle.rms_px, rms);
    if (!out.last_bundle.usable || !(rms <= options.max_added_rms_px)) {
      scene = before;
      out.last_bundle = before_bundle;
      given_up[k] = true;
      out.reasons[k] = fmt::format(
          "it does not fit the network: reprojection error {:.1f} px after adding it through {} "
          "and {}",
          rms, cameras[p].id, cameras[q].id);
      continue;
    }
    out.added_by[k] = "linked to " + cameras[p].id + " and " + cameras[q].id;
    if (progress) progress->Advance();
  }
  for (size_t k = 0; k < n; ++k) {
    if (!scene.present[k] && out.reasons[k].empty())
      out.reasons[k] = ReasonNotPlaced(graph, scene.present, k);
  }
  return out;
}

}  // namespace silnet::aggregator
