// The bundle adjustments' residuals with analytic derivatives (Euclidean and projective),
// against the camera model's own projection and against central differences.

#include "aggregator/calibration/reprojection_cost.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <random>
#include <string>
#include <vector>

#include "aggregator/calibration/projective_reprojection_cost.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {
namespace {

// One random configuration: intrinsics with distortion, a pose whose rotation angle is
// `angle`, a point in front of the camera, an observation near its pixel.
struct Configuration {
  std::array<double, 9> k;
  std::array<double, 6> pose;
  std::array<double, 3> world;
  Eigen::Vector2d observed;
  std::array<double*, 3> Blocks() { return {k.data(), pose.data(), world.data()}; }
};

Configuration RandomConfiguration(std::mt19937_64& rng, double angle) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Configuration c;
  c.k = {600 + 100 * u(rng), 600 + 100 * u(rng), 320 + 20 * u(rng), 240 + 20 * u(rng), 0.3 * u(rng),
         0.1 * u(rng),       0.01 * u(rng),      0.01 * u(rng),     0.05 * u(rng)};
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  const Eigen::Vector3d w = angle * axis;
  const Eigen::Vector3d t(u(rng), u(rng), 4.0 + u(rng));
  c.pose = {w.x(), w.y(), w.z(), t.x(), t.y(), t.z()};
  // A point in front: a camera-frame point carried back to the world.
  const Eigen::Matrix3d r = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  const Eigen::Vector3d x_cam(0.5 * u(rng), 0.4 * u(rng), 1.0 + 0.5 * (1.0 + u(rng)));
  const Eigen::Vector3d world = r.transpose() * (x_cam - t);
  c.world = {world.x(), world.y(), world.z()};
  c.observed = Eigen::Vector2d(320 + 300 * u(rng), 240 + 200 * u(rng));
  return c;
}

CameraModel ModelOf(const Configuration& c, bool square) {
  CameraModel m;
  m.K << c.k[0], 0.0, c.k[2], 0.0, square ? c.k[0] : c.k[1], c.k[3], 0.0, 0.0, 1.0;
  m.dist << c.k[4], c.k[5], c.k[6], c.k[7], c.k[8];
  const Eigen::Vector3d w(c.pose[0], c.pose[1], c.pose[2]);
  m.R = w.norm() > 0.0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                       : Eigen::Matrix3d::Identity();
  m.t = Eigen::Vector3d(c.pose[3], c.pose[4], c.pose[5]);
  return m;
}

// Every Jacobian `cost` gives at `blocks` against central differences of its residuals.
void ExpectJacobiansMatchCentralDifferences(const ceres::CostFunction& cost,
                                            std::vector<double*> blocks, const std::string& where) {
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  const int rows = cost.num_residuals();
  std::vector<std::vector<double>> storage;
  std::vector<double*> jacobians;
  for (int32_t size : sizes) {
    storage.emplace_back(static_cast<size_t>(rows * size));
    jacobians.push_back(storage.back().data());
  }
  std::vector<double> r(static_cast<size_t>(rows)), plus(r.size()), minus(r.size());
  ASSERT_TRUE(cost.Evaluate(blocks.data(), r.data(), jacobians.data())) << where;
  for (size_t block = 0; block < sizes.size(); ++block) {
    for (int p = 0; p < sizes[block]; ++p) {
      double* value = blocks[block] + p;
      const double saved = *value;
      const double step = 1e-6 * std::max(1.0, std::abs(saved));
      *value = saved + step;
      ASSERT_TRUE(cost.Evaluate(blocks.data(), plus.data(), nullptr)) << where;
      *value = saved - step;
      ASSERT_TRUE(cost.Evaluate(blocks.data(), minus.data(), nullptr)) << where;
      *value = saved;
      for (int row = 0; row < rows; ++row) {
        const double numeric =
            (plus[static_cast<size_t>(row)] - minus[static_cast<size_t>(row)]) / (2.0 * step);
        const double analytic = jacobians[block][static_cast<size_t>(row * sizes[block] + p)];
        EXPECT_NEAR(analytic, numeric, 1e-5 * std::max(1.0, std::abs(numeric)))
            << where << " block " << block << " parameter " << p << " row " << row;
      }
    }
  }
}

// Residuals against the camera model's pixel, Jacobians against central differences; square
// and free pixel aspect alternate, and tiny rotations take the series branch.
TEST(ReprojectionCost, ResidualIsTheCameraModelsPixelAndJacobiansMatchCentralDifferences) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(0.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const bool square = trial % 2 == 0;
    Configuration c = RandomConfiguration(rng, trial % 10 == 0 ? 1e-9 : angle(rng));
    const ReprojectionCost cost(c.observed, square);
    double r[2];
    ASSERT_TRUE(cost.Evaluate(c.Blocks().data(), r, nullptr));
    const auto pixel = ModelOf(c, square).Project(Eigen::Vector3d(c.world.data()));
    ASSERT_TRUE(pixel.has_value());
    EXPECT_NEAR(r[0], pixel->x() - c.observed.x(), 1e-9) << trial;
    EXPECT_NEAR(r[1], pixel->y() - c.observed.y(), 1e-9) << trial;
    const std::array<double*, 3> blocks = c.Blocks();
    ExpectJacobiansMatchCentralDifferences(cost, {blocks.begin(), blocks.end()},
                                           "trial " + std::to_string(trial));
  }
}

TEST(ReprojectionCost, APointOnThePrincipalPlaneHasNoResidual) {
  const std::array<double, 9> k = {600, 600, 320, 240, 0, 0, 0, 0, 0};
  const std::array<double, 6> pose = {0, 0, 0, 0, 0, 0};
  const std::array<double, 3> world = {0.3, 0.2, 0.0};
  const std::array<const double*, 3> blocks = {k.data(), pose.data(), world.data()};
  double r[2];
  EXPECT_FALSE(ReprojectionCost({320, 240}, true).Evaluate(blocks.data(), r, nullptr));
}

TEST(ProjectiveReprojectionCost, ResidualsAndJacobians) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::array<double, 12> p;
    for (double& v : p)
      v = u(rng);
    p[11] = 5.0;  // with x[3] >= 1: (P X)_z >= 2
    std::array<double, 4> x = {u(rng), u(rng), u(rng), 1.25 + 0.25 * u(rng)};
    const Eigen::Vector2d observed(u(rng), u(rng));
    const double scale = 400.0 + 100.0 * u(rng);
    const ProjectiveReprojectionCost cost(observed, scale);
    const Eigen::Vector2d expected =
        (Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(p.data()) *
         Eigen::Map<const Eigen::Vector4d>(x.data()))
            .hnormalized();
    const std::array<const double*, 2> blocks = {p.data(), x.data()};
    double r[2];
    ASSERT_TRUE(cost.Evaluate(blocks.data(), r, nullptr));
    EXPECT_NEAR(r[0], (expected.x() - observed.x()) * scale, 1e-9);
    EXPECT_NEAR(r[1], (expected.y() - observed.y()) * scale, 1e-9);
    ExpectJacobiansMatchCentralDifferences(cost, {p.data(), x.data()},
                                           "trial " + std::to_string(trial));
  }
}

}  // namespace
}  // namespace silnet::aggregator
