// Carving the hull on the lattice by views whose silhouettes the image border cuts: cells a
// border view sees as background are cleared, and given back where another view's silhouette
// would otherwise see nothing.

#include "aggregator/stereo/stereo_hull.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "aggregator/stereo/lattice_ray.h"
#include "aggregator/stereo/model_evaluation.h"

namespace silnet::aggregator {
namespace {

// A camera 1 m above the origin looking down +z, 100x100 px, focal 400 px.
CameraModel TopCamera(const std::string& id) {
  CameraModel camera;
  camera.id = id;
  camera.width = 100;
  camera.height = 100;
  camera.K << 400, 0, 49.5, 0, 400, 49.5, 0, 0, 1;
  camera.R.setIdentity();
  camera.t = Eigen::Vector3d(0, 0, 1);
  return camera;
}

// A full 20^3 cube of 1 cm cells around the origin.
VoxelGrid FullCube() {
  VoxelGrid grid = VoxelGrid::Empty(Eigen::Vector3d::Constant(-0.1), 0.01, {20, 20, 20});
  std::fill(grid.occupied.begin(), grid.occupied.end(), 1);
  return grid;
}

// One view: `camera` with a 100x100 silhouette of the pixels in `rows` x `cols`.
CutSilhouettes OneView(const CameraModel& camera, const cv::Range& rows, const cv::Range& cols) {
  CutSilhouettes view;
  view.cameras.push_back(camera);
  view.masks.push_back(cv::Mat::zeros(100, 100, CV_8UC1));
  view.masks[0](rows, cols).setTo(255);
  return view;
}

// True if the ray through every pixel at least 1 px inside `mask` meets an occupied cell.
bool EveryInnerRayMeetsACell(const CameraModel& camera, const cv::Mat& mask,
                             const VoxelGrid& grid) {
  const cv::Mat inner = InnerSilhouettePixels(mask, 1.0);
  const Eigen::Matrix3d back = camera.R.transpose() * camera.K.inverse();
  for (int y = 0; y < inner.rows; ++y) {
    for (int x = 0; x < inner.cols; ++x) {
      if (inner.at<uint8_t>(y, x) == 0) continue;
      bool met = false;
      WalkRay(grid, camera.Center(), (back * Eigen::Vector3d(x, y, 1)).normalized(),
              [&](double, size_t cell) { met = met || grid.occupied[cell] != 0; });
      if (!met) {
        ADD_FAILURE() << "the ray of pixel " << x << "," << y << " meets no cell";
        return false;
      }
    }
  }
  return true;
}

TEST(BorderCarving, ClearsWhatABorderViewSeesAsBackgroundAndGivesBackWhatAnotherViewNeeds) {
  VoxelGrid grid = FullCube();
  // The border view: silhouette = the image's left half (it touches the left border).
  const CutSilhouettes border = OneView(TopCamera("border"), cv::Range::all(), cv::Range(0, 50));
  // The bounded view, from the same place: a silhouette well right of the middle, which the
  // border view calls background (a shadow read as backdrop).
  const CutSilhouettes bounded =
      OneView(TopCamera("bounded"), cv::Range(30, 70), cv::Range(70, 90));

  const BorderCarving carving = CarveByBorderViews(border, bounded, 1.0, &grid);
  EXPECT_EQ(carving.carved, 20u * 20u * 10u);  // every cell right of x = 0
  EXPECT_GT(carving.restored, 0u);
  EXPECT_LT(carving.restored, carving.carved / 3);  // the columns under its silhouette
  const CameraModel& camera = bounded.cameras[0];
  for (int k = 0; k < 20; ++k) {
    for (int j = 0; j < 20; ++j) {
      for (int i = 0; i < 20; ++i) {
        const Eigen::Vector3d centre = grid.Center(i, j, k);
        const Eigen::Vector2d uv = *camera.Project(centre);
        const bool occupied = grid.IsOccupied(i, j, k);
        if (centre.x() < 0) {
          EXPECT_TRUE(occupied) << "left half carved at " << centre.transpose();
        } else if (uv.x() < 66 || uv.x() > 93 || uv.y() < 26 || uv.y() > 73) {
          // Far from the bounded view's silhouette: carved and not given back.
          EXPECT_FALSE(occupied) << "restored at " << uv.transpose();
        }
      }
    }
  }
  // The ray of every inner pixel of the bounded view meets an occupied cell again, and one
  // cell per ray at most was given back.
  EXPECT_TRUE(EveryInnerRayMeetsACell(camera, bounded.masks[0], grid));
  EXPECT_LE(carving.restored, static_cast<size_t>(cv::countNonZero(bounded.masks[0])));
}

TEST(BorderCarving, GivesBackTheCellTheBorderViewSeesLeastFarOutside) {
  // A border view from the side, at (-1, 0, 0) looking along +x, whose silhouette is its bottom
  // five rows: it sees the whole cube as background, the higher a cell (world z, its image
  // rows), the nearer its silhouette.
  VoxelGrid grid = FullCube();
  CameraModel side = TopCamera("side");
  side.R << 0, 1, 0, 0, 0, 1, 1, 0, 0;  // image x = world y, image y = world z
  side.t = -side.R * Eigen::Vector3d(-1, 0, 0);
  const CutSilhouettes border = OneView(side, cv::Range(95, 100), cv::Range::all());
  // The top view's silhouette, a square in the middle: its rays run up through the cube.
  const CutSilhouettes bounded = OneView(TopCamera("top"), cv::Range(40, 60), cv::Range(40, 60));
  const BorderCarving carving = CarveByBorderViews(border, bounded, 1.0, &grid);
  EXPECT_EQ(carving.carved, grid.size());
  EXPECT_GT(carving.restored, 0u);
  EXPECT_TRUE(EveryInnerRayMeetsACell(bounded.cameras[0], bounded.masks[0], grid));
  // Every cell given back is the top one of its column (the old rule gave back whole columns).
  for (int k = 0; k + 1 < 20; ++k) {
    for (int j = 0; j < 20; ++j) {
      for (int i = 0; i < 20; ++i)
        EXPECT_FALSE(grid.IsOccupied(i, j, k)) << i << "," << j << "," << k;
    }
  }
}

TEST(BorderCarving, OutsideItsImageABorderViewCarvesNothing) {
  VoxelGrid grid = FullCube();
  CameraModel camera = TopCamera("border");
  camera.K(0, 2) = -60;  // the cube now projects left of the image, mostly
  const CutSilhouettes border = OneView(camera, cv::Range::all(), cv::Range(0, 1));
  const BorderCarving carving = CarveByBorderViews(border, {}, 1.0, &grid);
  for (int k = 0; k < 20; ++k) {
    for (int j = 0; j < 20; ++j) {
      for (int i = 0; i < 20; ++i) {
        const Eigen::Vector2d uv = *border.cameras[0].Project(grid.Center(i, j, k));
        EXPECT_EQ(grid.IsOccupied(i, j, k), uv.x() < 0.5) << uv.transpose();
      }
    }
  }
  EXPECT_EQ(carving.restored, 0u);
}

}  // namespace
}  // namespace silnet::aggregator
