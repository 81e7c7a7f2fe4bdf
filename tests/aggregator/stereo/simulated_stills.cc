#include "tests/aggregator/stereo/simulated_stills.h"

#include <gtest/gtest.h>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/stereo/stills_folder.h"
#include "shared/io/point_cloud_ply.h"
#include "sim/stills_generator.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator::testing {

SimulatedStills MakeSimulatedStills(int cameras, int width, int height, uint64_t seed) {
  silnet::testing::TempDir dir("silnet-stills");
  sim::StillsOptions options;
  options.network.cameras = cameras;
  options.network.width = width;
  options.network.height = height;
  options.seed = seed;
  options.overwrite = true;
  const sim::StillsSummary summary = sim::GenerateStills(options, dir.path(), nullptr);
  SimulatedStills out;
  out.footprint = summary.footprint;
  out.views = LoadStillsFolder(dir.path(), dir.path() / "calibration.yaml");
  const OrientedPointCloud cloud = ReadPointCloudPly(dir.path() / "gt_surface.ply");
  for (size_t k = 0; k < cloud.points.size(); ++k) {
    out.truth.push_back(cloud.points[k].cast<double>());
    out.normals.push_back(cloud.normals[k].cast<double>().normalized());
  }
  const PolyhedralHullResult hull = ComputePolyhedralHull(out.views.Cameras(), out.views.Masks());
  EXPECT_TRUE(hull.success) << hull.reason;
  out.hull = hull.mesh;
  return out;
}

}  // namespace silnet::aggregator::testing
