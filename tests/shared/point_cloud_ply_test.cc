#include "shared/io/point_cloud_ply.h"

#include <gtest/gtest.h>

#include <fstream>

#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

TEST(PointCloudPly, RoundTripsPointsNormalsAndComments) {
  testing::TempDir dir;
  OrientedPointCloud cloud;
  cloud.comments = {"made by a test", "spacing_m 0.003"};
  for (int i = 0; i < 1000; ++i) {
    cloud.points.emplace_back(0.001f * static_cast<float>(i), -1.5f,
                              3.25e-4f * static_cast<float>(i));
    cloud.normals.push_back(Eigen::Vector3f(1.0f, static_cast<float>(i), 0.0f).normalized());
  }
  const std::size_t bytes = WritePointCloudPly(dir / "c.ply", cloud);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "c.ply"));
  const OrientedPointCloud read = ReadPointCloudPly(dir / "c.ply");
  EXPECT_EQ(read.comments, cloud.comments);
  ASSERT_EQ(read.points.size(), cloud.points.size());
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    EXPECT_EQ(read.points[i], cloud.points[i]);
    EXPECT_EQ(read.normals[i], cloud.normals[i]);
  }
}

TEST(PointCloudPly, RejectsOtherLayoutsAndTruncatedFiles) {
  testing::TempDir dir;
  OrientedPointCloud cloud;
  cloud.points.assign(10, Eigen::Vector3f::Zero());
  cloud.normals.assign(10, Eigen::Vector3f::UnitZ());
  WritePointCloudPly(dir / "c.ply", cloud);
  std::filesystem::resize_file(dir / "c.ply", std::filesystem::file_size(dir / "c.ply") - 4);
  EXPECT_THROW(ReadPointCloudPly(dir / "c.ply"), InputError);
  std::ofstream(dir / "ascii.ply") << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                      "property float y\nproperty float z\nend_header\n0 0 0\n";
  EXPECT_THROW(ReadPointCloudPly(dir / "ascii.ply"), InputError);
  EXPECT_THROW(ReadPointCloudPly(dir / "missing.ply"), InputError);
  cloud.normals.pop_back();
  EXPECT_THROW(WritePointCloudPly(dir / "d.ply", cloud), CheckError);
}

}  // namespace
}  // namespace silnet
