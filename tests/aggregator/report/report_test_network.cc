#include "tests/aggregator/report/report_test_network.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace silnet::aggregator::testing {

NetworkCalibration MakeTestCalibration(const TestNetworkOptions& o) {
  std::mt19937_64 rng(o.seed);
  NetworkCalibration c;
  c.cameras = sim::MakeCameraNetwork(o.network);
  const size_t n = c.cameras.size();
  std::vector<size_t> placed;
  c.placement.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (o.unplaced.count(i) != 0) {
      c.placement[i].reason = "epipoles inside the silhouettes in 80 % of frames";
    } else {
      c.placement[i].placed = true;
      c.placement[i].added_by = placed.size() < 3 ? "initial triplet" : "resection";
      placed.push_back(i);
    }
  }

  // Frontier points: random points in the capture area seen by two random placed cameras.
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, o.pixel_noise);
  std::uniform_int_distribution<size_t> pick(0, placed.empty() ? 0 : placed.size() - 1);
  for (int k = 0; k < o.points && placed.size() >= 2; ++k) {
    const Eigen::Vector3d X(uniform(rng), uniform(rng), 0.9 + 0.8 * uniform(rng));
    size_t a = placed[pick(rng)], b = placed[pick(rng)];
    while (b == a)
      b = placed[pick(rng)];
    const bool outlier = k < o.outlier_fraction * o.points;
    FrontierPoint p;
    p.X = X;
    p.frame = static_cast<uint64_t>(k);
    p.inlier = !outlier;
    const size_t cams[2] = {a, b};
    for (int v = 0; v < 2; ++v) {
      const Eigen::Vector2d projected = c.cameras[cams[v]].Project(X).value();
      Eigen::Vector2d offset(noise(rng), noise(rng));
      if (outlier)
        offset =
            Eigen::Vector2d(uniform(rng), uniform(rng)).normalized() * (12.5 + 7.5 * uniform(rng));
      p.views[v].camera = cams[v];
      p.views[v].pixel = projected + offset;
      p.views[v].error_px = offset.norm();
      if (p.inlier) ++c.placement[cams[v]].observations;
    }
    c.points.push_back(p);
  }
  std::vector<double> all;
  for (size_t i = 0; i < n; ++i) {
    std::vector<double> e;
    for (const FrontierPoint& p : c.points) {
      for (const FrontierObservation& v : p.views) {
        if (p.inlier && v.camera == i) e.push_back(v.error_px);
      }
    }
    all.insert(all.end(), e.begin(), e.end());
    double sum = 0.0;
    for (double x : e)
      sum += x * x;
    c.placement[i].rms_px = e.empty() ? 0.0 : std::sqrt(sum / e.size());
    std::sort(e.begin(), e.end());
    c.placement[i].median_px = e.empty() ? 0.0 : e[e.size() / 2];
  }
  double sum = 0.0;
  for (double x : all)
    sum += x * x;
  c.rms_px = all.empty() ? 0.0 : std::sqrt(sum / all.size());
  std::sort(all.begin(), all.end());
  c.median_px = all.empty() ? 0.0 : all[all.size() / 2];

  // Synchronisation around the true offsets, reference = first placed camera.
  SyncResult& s = c.sync;
  s.reference = placed.empty() ? 0 : placed[0];
  s.offsets.assign(n, 0.0);
  s.sigmas.assign(n, 0.0);
  s.synchronised.assign(n, false);
  s.reasons.assign(n, "not connected to the reference");
  for (size_t i : placed) {
    s.offsets[i] = c.cameras[i].time_offset - c.cameras[s.reference].time_offset;
    s.sigmas[i] = i == s.reference ? 0.0 : 0.01;
    s.synchronised[i] = true;
    s.reasons[i].clear();
  }
  std::normal_distribution<double> offset_noise(0.0, 0.02);
  for (size_t a = 0; a < placed.size(); ++a) {
    for (size_t step : {1, 2}) {
      if (placed.size() < 3 && step == 2) continue;
      const size_t i = placed[a], j = placed[(a + step) % placed.size()];
      if (i == j) continue;
      SyncEdgeResult e;
      e.edge = {i, j, s.offsets[i] - s.offsets[j] + offset_noise(rng), 0.03};
      e.used = true;
      e.cycles = 4;
      e.residual = e.edge.offset - (s.offsets[i] - s.offsets[j]);
      s.edges.push_back(e);
    }
  }
  if (!s.edges.empty()) {
    SyncEdgeResult& bad = s.edges[s.edges.size() / 2];
    bad.edge.offset += 3.0;
    bad.residual += 3.0;
    bad.used = false;
    bad.cycles_failed = 3;
    bad.rejection = "cycle test: 3 of 4 cycles failed";
  }
  s.rms_residual = 0.02;
  s.rms_normalised = 0.7;

  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      PairCheck p;
      p.i = i;
      p.j = j;
      const bool usable = c.placement[i].placed && c.placement[j].placed;
      p.pairwise_status = usable ? PairStatus::kOk : PairStatus::kDegenerate;
      p.pairwise_reason = usable ? "" : "epipole inside the hull in 80 % of frames";
      p.used = usable && j == i + 1;
      p.distance_px = usable ? 0.4 : -1.0;
      p.corrected = i == 0 && j == 3;
      p.note = p.corrected ? "estimate 25 px from the derived F" : "";
      c.pairs.push_back(p);
    }
  }
  c.stages = {{"projective reconstruction", 0.8, 1.5, "initial triplet cam00 cam01 cam02"},
              {"Euclidean bundle adjustment", c.rms_px, 2.25, "radial distortion k1, k2"}};
  return c;
}

}  // namespace silnet::aggregator::testing
