#include "aggregator/pairwise/frontier_matching.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

#include "shared/geometry/epipolar.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

testing::SimCapture SyncCapture(int frames, uint64_t seed = 2) {
  sim::CameraNetworkOptions network;
  network.cameras = 4;
  network.max_offset = 0.0;
  network.seed = seed;
  sim::SceneOptions scene;
  scene.seed = seed;
  return testing::MakeSimCapture(network, scene, frames);
}

TEST(EpipolarModel, RoundTripsAFundamentalMatrix) {
  const auto capture = SyncCapture(1);
  for (size_t j = 1; j < capture.cameras.size(); ++j) {
    const Eigen::Matrix3d f = FundamentalFromCameras(capture.cameras[0], capture.cameras[j]);
    const EpipolarModel model = EpipolarModel::FromFundamental(f);
    const Eigen::Matrix3d back = NormalizeFundamental(model.Fundamental());
    EXPECT_LT((back - f).norm(), 1e-9);
    const Eigen::Vector2d x(100, 200);
    EXPECT_LT((model.LineInJ(x).normalized() - (f * x.homogeneous()).normalized()).norm() *
                  (model.LineInJ(x).normalized() + (f * x.homogeneous()).normalized()).norm(),
              1e-9);
  }
}

TEST(FrontierMatching, GroundTruthGeometryMatchesFrontierPointsToSubPixelError) {
  const auto capture = SyncCapture(120);
  size_t checked = 0;
  for (size_t j = 1; j < capture.cameras.size(); ++j) {
    const Eigen::Matrix3d f = FundamentalFromCameras(capture.cameras[0], capture.cameras[j]);
    const EpipolarModel model = EpipolarModel::FromFundamental(f);
    std::vector<double> errors;
    for (uint64_t k = 0; k < 120; ++k) {
      const SilhouetteFrame* fi = capture.sequences[0].Usable(k);
      const SilhouetteFrame* fj = capture.sequences[j].Usable(k);
      if (fi == nullptr || fj == nullptr) continue;
      FrontierMatch matches[2];
      const int n = MatchTangents(model, ComputeOuterTangents(fi->hull, model.pencil_i.e),
                                  ComputeOuterTangents(fj->hull, model.pencil_j.e), matches);
      for (int m = 0; m < n; ++m)
        errors.push_back(TransferError(f, matches[m].x_i, matches[m].x_j));
    }
    if (errors.size() < 40) continue;  // epipoles inside the silhouettes: no frontier points
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2];
    EXPECT_LT(median, 1.0) << "pair 0-" << j;
    ++checked;
  }
  EXPECT_GE(checked, 2u);
}

TEST(LineHomography, ThreeExactCorrespondencesRecoverTheHomography) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    EpipolarModel truth;
    truth.pencil_i =
        PencilBasis::For(Eigen::Vector3d(u(rng) * 2000, u(rng) * 2000, trial % 5 == 0 ? 0.0 : 1.0));
    truth.pencil_j = PencilBasis::For(Eigen::Vector3d(u(rng) * 2000, u(rng) * 2000, 1.0));
    truth.h << u(rng), u(rng), u(rng), u(rng);
    std::array<Eigen::Vector3d, 3> li, lj;
    for (size_t k = 0; k < 3; ++k) {
      const Eigen::Vector2d c(u(rng), u(rng));
      li[k] = truth.pencil_i.Line(c) * (1.0 + 3.0 * std::abs(u(rng)));
      lj[k] = truth.pencil_j.Line(truth.h * c) * -2.0;
    }
    const auto h = SolveLineHomography(truth.pencil_i, truth.pencil_j, li, lj);
    ASSERT_TRUE(h.has_value());
    // Equal up to scale.
    const Eigen::Matrix2d a = truth.h / truth.h.norm(), b = *h / h->norm();
    EXPECT_LT(std::min((a - b).norm(), (a + b).norm()), 1e-8) << "trial " << trial;
  }
  // Two coinciding lines make the system degenerate.
  const PencilBasis p = PencilBasis::For(Eigen::Vector3d(1, 2, 1));
  EXPECT_FALSE(SolveLineHomography(p, p, {p.u, p.u, p.v}, {p.u, p.v, p.u}).has_value());
}

}  // namespace
}  // namespace silnet::aggregator
