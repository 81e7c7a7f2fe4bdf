#pragma once
// The viewing-cone faces of a set of calibrated silhouettes (thesis 4.2): one plane per
// contour edge, with the indexes the exact polyhedral hull needs to stay fast: for every
// camera pair, the contour edges ordered by the epipolar half-plane they span (so a face
// meets only the other view's edges in its own epipolar range), and per camera a row index
// for point-in-silhouette tests and a grid of image cells for the edges near a short segment.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"
#include "shared/silhouette/silhouette_contour.h"

namespace silnet::aggregator {

// A contour edge p -> q of one camera's silhouette (undistorted pixels, silhouette on its
// left) and so the plane of one viewing-cone face. `prev` / `next` are the planes of the edges
// before and after it on the same ring.
struct ConePlane {
  int view = 0;
  Eigen::Vector2d p, q;
  int prev = -1, next = -1;
};

// The epipolar half-plane (pseudo-)angles a contour edge spans, about one camera pair's baseline.
struct EdgeArc {
  double lo = 0, hi = 0;
  int plane = -1;
};

// Sorts `arcs` by lo, then plane, merging the ascending and descending runs they come in (few
// where they follow a contour); `buffer` is scratch room, kept by the caller between calls.
void SortArcs(std::vector<EdgeArc>& arcs, std::vector<EdgeArc>& buffer);

// Every camera's cone planes and their indexes.
class ConePlaneSet {
 public:
  // Builds the planes from one outline per camera (distortion removed) and indexes them for
  // hulls inside `bounds` (which must not contain a camera centre). Every contour point is
  // moved by a fixed pseudo-random offset of at most `perturbation_px` per coordinate (a
  // function of its camera and index alone, so the same input always gives the same planes):
  // exact coincidences of cameras and contours (a symmetric ring, where contour vertices lie
  // on the image row every camera centre projects to) would otherwise make four or more cone
  // faces meet at one point, which the faces, computed each on its own, decide differently.
  // The indexes are built on `threads` threads; they do not depend on the number.
  ConePlaneSet(const std::vector<CameraModel>& cameras,
               const std::vector<SilhouetteContours>& contours, const WorldBox& bounds,
               double perturbation_px = 0, int threads = 1);

  const std::vector<ConePlane>& Planes() const { return planes_; }
  const ConePlane& Plane(int index) const { return planes_[static_cast<size_t>(index)]; }
  size_t Views() const { return view_planes_.size(); }
  // Camera `view`'s undistorted projection matrix.
  const Matrix34d& Projection(int view) const { return projections_[static_cast<size_t>(view)]; }
  // The world normal of plane `index` (the cross product of its rays through p and q).
  const Eigen::Vector3d& Normal(int index) const { return normals_[static_cast<size_t>(index)]; }
  // World direction of the ray through an undistorted pixel of `view`, at unit depth.
  Eigen::Vector3d Ray(int view, const Eigen::Vector2d& pixel) const;
  // Ray(view, p) of plane `index`, computed once: the ray through its first contour point
  // (the ray through its last, q, is that of the next plane, whose p it is).
  const Eigen::Vector3d& RayThroughP(int index) const { return rays_[static_cast<size_t>(index)]; }
  // Eight half-planes (line . (x, y, 1) >= 0 inside) bounding `view`'s silhouette in
  // undistorted pixels with a margin of one pixel: its bounding octagon (axes and diagonals).
  const std::array<Eigen::Vector3d, 8>& BoundingOctagon(int view) const {
    return octagons_[static_cast<size_t>(view)];
  }
  // True if an undistorted pixel of `view` lies inside its silhouette (even-odd rule).
  bool Contains(int view, const Eigen::Vector2d& pixel) const;
  // Appends the planes of camera `other` whose epipolar range about the baseline to camera
  // `view` can meet the range of the rays `from` and `to` of `view` (world directions).
  void CandidateEdges(int view, int other, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                      std::vector<int>& out) const;
  // Appends the planes of camera `view` filed in the cells of its grid that the segment from
  // undistorted image point `a` to `b` passes (every contour edge within half a pixel of the
  // segment, so every edge it meets; one filed in several of those cells more than once) and
  // returns true; returns false, appending nothing, if the segment passes more than
  // `max_cells` cells (a long segment, for which CandidateEdges offers fewer).
  bool EdgesNearSegment(int view, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        size_t max_cells, std::vector<int>& out) const;

 private:
  struct PairIndex {
    Eigen::Vector3d u1, u2;     // basis of the plane normal to the baseline
    std::vector<EdgeArc> arcs;  // sorted by lo, then plane
    std::vector<double> reach;  // per arc: the largest hi of the arcs up to it (non-decreasing)
    std::vector<int> wide;      // planes whose range could not be bounded
  };
  // A contour edge a -> b as the point-in-silhouette test reads it: its ends' heights and the
  // line x = ax + dx_dy (y - ay).
  struct RowEdge {
    double ax = 0, ay = 0, by = 0, dx_dy = 0;
  };
  // The contour edges whose y-range meets each row, stored in the row so a point-in-silhouette
  // test reads one contiguous run: row r's edges are edges[starts[r], starts[r + 1]).
  struct RowIndex {
    double y0 = 0;  // rows are kRowStepPx high (cone_plane_set.cc)
    std::vector<uint32_t> starts;
    std::vector<RowEdge> edges;

    size_t Rows() const { return starts.empty() ? 0 : starts.size() - 1; }
  };
  // The contour edges that pass near each square image cell: cell (c, r)'s planes are
  // planes[starts[i], starts[i + 1]) for i = r * cols + c; the grid covers the view's contour
  // points with a margin.
  struct CellIndex {
    double x0 = 0, y0 = 0;  // cells are kCellPx wide (cone_plane_set.cc)
    int cols = 0, rows = 0;
    std::vector<uint32_t> starts;
    std::vector<int> planes;
  };
  // The cell index of the planes `view_planes` (one view's).
  static CellIndex BuildCellIndex(const std::vector<ConePlane>& planes,
                                  const std::vector<int>& view_planes);
  // The direction's angle about the pair's baseline, as an order-preserving pseudo-angle.
  double Angle(const PairIndex& pair, const Eigen::Vector3d& direction) const;

  std::vector<ConePlane> planes_;
  std::vector<Eigen::Vector3d> rays_;  // per plane: the world direction of its ray through p
  std::vector<Eigen::Vector3d> normals_;
  std::vector<std::vector<int>> view_planes_;
  std::vector<Matrix34d> projections_;
  std::vector<Eigen::Matrix3d> pixel_to_ray_;
  std::vector<RowIndex> rows_;
  std::vector<CellIndex> cells_;
  std::vector<std::array<Eigen::Vector3d, 8>> octagons_;
  std::vector<PairIndex> pairs_;  // [view * Views() + other]
};

}  // namespace silnet::aggregator
