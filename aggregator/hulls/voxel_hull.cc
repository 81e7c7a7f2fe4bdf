#include "aggregator/hulls/voxel_hull.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "aggregator/hulls/viewing_cone_bounds.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// What one camera says about all voxel centres of a cell.
enum class Verdict {
  kKeep,       // every centre is inside the silhouette or unseen: nothing to carve
  kCarve,      // every centre is seen and outside the silhouette
  kAmbiguous,  // some of each, or cannot tell
};

// One camera prepared for carving: its projection and the silhouette's integral image.
struct CarvingView {
  const CameraModel* camera = nullptr;
  Matrix34d P;  // K [R | t], used when the camera has no distortion
  bool distorted = false;
  cv::Mat silhouette;  // CV_8UC1, 1 = silhouette
  cv::Mat integral;    // CV_32SC1, (h + 1) x (w + 1) sums of `silhouette`

  // Pixel of a world point; false if the point is behind the camera.
  bool Project(const Eigen::Vector3d& X, Eigen::Vector2d* uv) const {
    if (distorted) {
      const auto p = camera->Project(X);
      if (!p) return false;
      *uv = *p;
      return true;
    }
    const Eigen::Vector3d x = P * X.homogeneous();
    if (!(x.z() > 0.0)) return false;
    *uv = x.head<2>() / x.z();
    return true;
  }

  // Verdict on a single centre.
  Verdict PointVerdict(const Eigen::Vector3d& X) const {
    Eigen::Vector2d uv;
    if (!Project(X, &uv)) return Verdict::kKeep;
    const double px = std::floor(uv.x() + 0.5), py = std::floor(uv.y() + 0.5);
    if (px < 0 || py < 0 || px >= camera->width || py >= camera->height) return Verdict::kKeep;
    return silhouette.at<uint8_t>(static_cast<int>(py), static_cast<int>(px)) != 0
               ? Verdict::kKeep
               : Verdict::kCarve;
  }

  // Verdict on all centres in the box [lo, hi] (world), from its projected rectangle.
  Verdict BoxVerdict(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double margin) const {
    double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d X((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                              (corner & 4) ? hi.z() : lo.z());
      Eigen::Vector2d uv;
      if (!Project(X, &uv)) return Verdict::kAmbiguous;
      u0 = std::min(u0, uv.x());
      u1 = std::max(u1, uv.x());
      v0 = std::min(v0, uv.y());
      v1 = std::max(v1, uv.y());
    }
    // Pixels the centres can fall on, then the part of them on the image.
    const double px0 = std::floor(u0 - margin + 0.5), px1 = std::floor(u1 + margin + 0.5);
    const double py0 = std::floor(v0 - margin + 0.5), py1 = std::floor(v1 + margin + 0.5);
    const double w = camera->width, h = camera->height;
    const bool partly_off_image = px0 < 0 || py0 < 0 || px1 >= w || py1 >= h;
    const int x0 = static_cast<int>(std::max(px0, 0.0)),
              x1 = static_cast<int>(std::min(px1, w - 1));
    const int y0 = static_cast<int>(std::max(py0, 0.0)),
              y1 = static_cast<int>(std::min(py1, h - 1));
    if (px1 < 0 || py1 < 0 || px0 >= w || py0 >= h) return Verdict::kKeep;  // all off-image
    const int64_t area = static_cast<int64_t>(x1 - x0 + 1) * (y1 - y0 + 1);
    const int64_t sum = static_cast<int64_t>(integral.at<int32_t>(y1 + 1, x1 + 1)) -
                        integral.at<int32_t>(y0, x1 + 1) - integral.at<int32_t>(y1 + 1, x0) +
                        integral.at<int32_t>(y0, x0);
    if (sum == area) return Verdict::kKeep;
    if (sum == 0 && !partly_off_image) return Verdict::kCarve;
    return Verdict::kAmbiguous;
  }
};

CarvingView MakeCarvingView(const CameraModel& camera, const cv::Mat& mask) {
  CarvingView view;
  view.camera = &camera;
  view.P = camera.ProjectionMatrix();
  view.distorted = camera.HasDistortion();
  cv::threshold(mask, view.silhouette, 0, 1, cv::THRESH_BINARY);
  cv::integral(view.silhouette, view.integral, CV_32S);
  return view;
}

// Octree carving of one grid.
class OctreeCarver {
 public:
  OctreeCarver(const std::vector<CarvingView>& views, double margin, VoxelGrid* grid)
      : views_(views), margin_(margin), grid_(grid) {}

  // Carves the cell of `size` voxels per side at voxel (i, j, k); `pending` has one bit per
  // camera that has not yet kept the whole cell.
  void Carve(int i, int j, int k, int size, uint64_t pending) {
    const int i1 = std::min(i + size, grid_->dims[0]) - 1;
    const int j1 = std::min(j + size, grid_->dims[1]) - 1;
    const int k1 = std::min(k + size, grid_->dims[2]) - 1;
    if (i > i1 || j > j1 || k > k1) return;
    cells_visited_.fetch_add(1, std::memory_order_relaxed);
    const bool single = i == i1 && j == j1 && k == k1;
    const Eigen::Vector3d lo = grid_->Center(i, j, k), hi = grid_->Center(i1, j1, k1);
    if (single) voxels_tested_.fetch_add(1, std::memory_order_relaxed);
    for (size_t c = 0; c < views_.size(); ++c) {
      if (!(pending & (uint64_t{1} << c))) continue;
      const CarvingView& view = views_[c];
      const Verdict verdict =
          single ? view.PointVerdict(lo) : view.BoxVerdict(lo, hi, view.distorted ? margin_ : 0.0);
      if (verdict == Verdict::kCarve) return;  // grid starts carved
      if (verdict == Verdict::kKeep) pending &= ~(uint64_t{1} << c);
    }
    if (pending == 0) {
      for (int z = k; z <= k1; ++z) {
        for (int y = j; y <= j1; ++y) {
          uint8_t* row = &grid_->occupied[grid_->Index(i, y, z)];
          std::fill(row, row + (i1 - i + 1), uint8_t{1});
        }
      }
      return;
    }
    // Ambiguous for some camera (never for a single voxel: PointVerdict decides).
    const int half = size / 2;
    for (int child = 0; child < 8; ++child) {
      Carve(i + ((child & 1) ? half : 0), j + ((child & 2) ? half : 0),
            k + ((child & 4) ? half : 0), half, pending);
    }
  }

  VoxelHullStats Stats() const { return {cells_visited_.load(), voxels_tested_.load()}; }

 private:
  const std::vector<CarvingView>& views_;
  double margin_;
  VoxelGrid* grid_;
  std::atomic<size_t> cells_visited_{0};
  std::atomic<size_t> voxels_tested_{0};
};

}  // namespace

bool VoxelHullOptions::IsValid(std::string* reason) const {
  auto fail = [&](const char* why) {
    if (reason) *reason = why;
    return false;
  };
  if (!(voxel_size > 0.0)) return fail("voxel_size must be positive");
  if (bounds && bounds->isEmpty()) return fail("bounds must not be empty");
  if (!(bounds_padding_voxels >= 0.0)) return fail("bounds_padding_voxels must be >= 0");
  if (octree_levels < 0 || octree_levels > 12) return fail("octree_levels must lie in [0, 12]");
  if (threads < 0) return fail("threads must be >= 0");
  if (!(distortion_margin_px >= 0.0)) return fail("distortion_margin_px must be >= 0");
  return true;
}

VoxelHullResult CarveVoxelHull(const std::vector<CameraModel>& cameras,
                               const std::vector<cv::Mat>& masks, const VoxelHullOptions& options) {
  VoxelHullResult result;
  if (!options.IsValid(&result.reason)) return result;
  if (cameras.empty() || cameras.size() != masks.size()) {
    result.reason = "need one mask per camera";
    return result;
  }
  if (cameras.size() > 64) {
    result.reason = "at most 64 cameras";
    return result;
  }
  for (size_t c = 0; c < cameras.size(); ++c) {
    result.reason = MaskShapeProblem(cameras[c], masks[c]);
    if (!result.reason.empty()) return result;
  }
  WorldBox box;
  if (options.bounds) {
    box = *options.bounds;
  } else {
    const ViewingConeBounds cone_bounds = ComputeViewingConeBounds(cameras, masks);
    if (!cone_bounds.success) {
      result.reason = cone_bounds.reason;
      return result;
    }
    box = cone_bounds.box;
    box.min().array() -= options.bounds_padding_voxels * options.voxel_size;
    box.max().array() += options.bounds_padding_voxels * options.voxel_size;
  }
  result.grid = GridCovering(box, options.voxel_size);

  std::vector<CarvingView> views;
  views.reserve(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c)
    views.push_back(MakeCarvingView(cameras[c], masks[c]));

  const int top = 1 << options.octree_levels;
  const std::array<int, 3>& dims = result.grid.dims;
  const int ci = (dims[0] + top - 1) / top, cj = (dims[1] + top - 1) / top;
  const int ck = (dims[2] + top - 1) / top;
  const size_t top_cells =
      static_cast<size_t>(ci) * static_cast<size_t>(cj) * static_cast<size_t>(ck);
  const uint64_t all = cameras.size() == 64 ? ~uint64_t{0} : (uint64_t{1} << cameras.size()) - 1;
  OctreeCarver carver(views, options.distortion_margin_px, &result.grid);
  auto carve_top_cell = [&](size_t n) {
    const int i = static_cast<int>(n % static_cast<size_t>(ci));
    const int j = static_cast<int>((n / static_cast<size_t>(ci)) % static_cast<size_t>(cj));
    const int k = static_cast<int>(n / (static_cast<size_t>(ci) * static_cast<size_t>(cj)));
    carver.Carve(i * top, j * top, k * top, top, all);
  };
  // Top cells write disjoint voxels, so they may run in parallel.
  if (options.threads == 1) {
    for (size_t n = 0; n < top_cells; ++n)
      carve_top_cell(n);
  } else {
    ParallelFor(top_cells, options.threads, carve_top_cell);
  }
  result.stats = carver.Stats();
  result.success = true;
  return result;
}

bool VoxelCentreInHull(const std::vector<CameraModel>& cameras, const std::vector<cv::Mat>& masks,
                       const Eigen::Vector3d& centre) {
  for (size_t c = 0; c < cameras.size(); ++c) {
    const auto uv = cameras[c].Project(centre);
    if (!uv) continue;
    const double px = std::floor(uv->x() + 0.5), py = std::floor(uv->y() + 0.5);
    if (px < 0 || py < 0 || px >= cameras[c].width || py >= cameras[c].height) continue;
    if (masks[c].at<uint8_t>(static_cast<int>(py), static_cast<int>(px)) == 0) return false;
  }
  return true;
}

}  // namespace silnet::aggregator
