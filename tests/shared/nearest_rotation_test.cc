#include "shared/geometry/nearest_rotation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>

namespace silnet {
namespace {

TEST(NearestRotation, RoundedRotationsComeBackAndOtherMatricesAreRefused) {
  const Eigen::Matrix3d truth =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  // Printed to six decimals, as the datasets do.
  const Eigen::Matrix3d rounded = (truth * 1e6).array().round() / 1e6;
  const std::optional<Eigen::Matrix3d> back = NearestRotation(rounded, 1e-4);
  ASSERT_TRUE(back.has_value());
  EXPECT_LT((*back - truth).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((*back * back->transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(back->determinant(), 1.0, 1e-12);

  EXPECT_FALSE(NearestRotation(-truth, 1e-4)) << "a mirror";
  EXPECT_FALSE(NearestRotation(1.01 * truth, 1e-4)) << "scaled";
  Eigen::Matrix3d typo = truth;
  typo(1, 2) += 0.01;
  EXPECT_FALSE(NearestRotation(typo, 1e-4));
  EXPECT_TRUE(NearestRotation(typo, 0.02)) << "within a looser tolerance";
  typo(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(NearestRotation(typo, 1.0));
}

}  // namespace
}  // namespace silnet
