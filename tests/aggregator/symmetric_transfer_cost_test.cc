// The refinement's residual with analytic derivatives, against the fundamental matrix its
// parameters stand for and against central differences.

#include "aggregator/pairwise/symmetric_transfer_cost.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <random>

#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

struct Parameters {
  std::array<double, 3> e_i, e_j;
  std::array<double, 4> h;
  double offset;
  std::array<const double*, 4> Blocks() const {
    return {e_i.data(), e_j.data(), h.data(), &offset};
  }
};

Eigen::Vector3d Axis(const Eigen::Vector3d& e) {
  Eigen::Index k = 0;
  e.cwiseAbs().minCoeff(&k);
  return Eigen::Vector3d::Unit(k);
}

// Pencil basis [u v] (3 x 2) of a unit epipole from its reference axis.
Eigen::Matrix<double, 3, 2> PencilBasis(const Eigen::Vector3d& e, const Eigen::Vector3d& axis) {
  Eigen::Matrix<double, 3, 2> b;
  b.col(0) = axis.cross(e).normalized();
  b.col(1) = e.cross(b.col(0));
  return b;
}

TEST(SymmetricTransferCost, ResidualsAreDistancesToTheEpipolarLinesOfF) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), px(0.0, 640.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d e_i = Eigen::Vector3d(u(rng) * 900, u(rng) * 900, u(rng)).normalized();
    const Eigen::Vector3d e_j = Eigen::Vector3d(u(rng) * 900, u(rng) * 900, u(rng)).normalized();
    const TransferObservation o{{px(rng), px(rng)}, {px(rng), px(rng)}, {px(rng), px(rng)}, 0.3};
    const Parameters p{{e_i.x(), e_i.y(), e_i.z()},
                       {e_j.x(), e_j.y(), e_j.z()},
                       {u(rng), u(rng), u(rng), u(rng)},
                       0.2 * u(rng)};
    const SymmetricTransferCost cost(o, Axis(e_i), Axis(e_j));
    double r[2];
    ASSERT_TRUE(cost.Evaluate(p.Blocks().data(), r, nullptr));

    Eigen::Matrix2d h;
    h << p.h[0], p.h[1], p.h[2], p.h[3];
    const Eigen::Matrix3d f =
        PencilBasis(e_j, Axis(e_j)) * h * PencilBasis(e_i, Axis(e_i)).transpose() * Skew(e_i);
    const double blend = o.time_i + p.offset;
    const Eigen::Vector3d xi = o.x_i.homogeneous();
    const Eigen::Vector3d xj = ((1.0 - blend) * o.x_j_a + blend * o.x_j_b).homogeneous();
    const Eigen::Vector3d line_j = f * xi, line_i = f.transpose() * xj;
    EXPECT_NEAR(r[0], line_j.dot(xj) / line_j.head<2>().norm(), 1e-9 * (1.0 + std::abs(r[0])));
    EXPECT_NEAR(std::abs(r[1]), std::abs(line_i.dot(xi)) / line_i.head<2>().norm(),
                1e-9 * (1.0 + std::abs(r[1])));
  }
}

TEST(SymmetricTransferCost, JacobiansMatchCentralDifferences) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0), px(0.0, 640.0);
  const int sizes[4] = {3, 3, 4, 1};
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d e_i = Eigen::Vector3d(u(rng) * 900, u(rng) * 900, u(rng)).normalized();
    const Eigen::Vector3d e_j = Eigen::Vector3d(u(rng) * 900, u(rng) * 900, u(rng)).normalized();
    const TransferObservation o{{px(rng), px(rng)}, {px(rng), px(rng)}, {px(rng), px(rng)}, -0.6};
    Parameters p{{e_i.x(), e_i.y(), e_i.z()},
                 {e_j.x(), e_j.y(), e_j.z()},
                 {u(rng), u(rng), u(rng), u(rng)},
                 u(rng)};
    const SymmetricTransferCost cost(o, Axis(e_i), Axis(e_j));
    double r[2];
    std::array<std::array<double, 8>, 4> jacobian{};
    std::array<double*, 4> jacobians{jacobian[0].data(), jacobian[1].data(), jacobian[2].data(),
                                     jacobian[3].data()};
    ASSERT_TRUE(cost.Evaluate(p.Blocks().data(), r, jacobians.data()));
    double* blocks[4] = {p.e_i.data(), p.e_j.data(), p.h.data(), &p.offset};
    for (int b = 0; b < 4; ++b) {
      for (int c = 0; c < sizes[b]; ++c) {
        const double step = 1e-7 * std::max(1.0, std::abs(blocks[b][c]));
        const double kept = blocks[b][c];
        double plus[2], minus[2];
        blocks[b][c] = kept + step;
        ASSERT_TRUE(cost.Evaluate(p.Blocks().data(), plus, nullptr));
        blocks[b][c] = kept - step;
        ASSERT_TRUE(cost.Evaluate(p.Blocks().data(), minus, nullptr));
        blocks[b][c] = kept;
        for (int k = 0; k < 2; ++k) {
          const double numeric = (plus[k] - minus[k]) / (2.0 * step);
          const double analytic =
              jacobian[static_cast<size_t>(b)][static_cast<size_t>(k * sizes[b] + c)];
          EXPECT_NEAR(analytic, numeric, 1e-5 * (1.0 + std::abs(numeric)))
              << "trial " << trial << " block " << b << " column " << c << " residual " << k;
        }
      }
    }
  }
}

}  // namespace
}  // namespace silnet::aggregator
