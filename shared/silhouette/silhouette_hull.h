#pragma once
// The compact silhouette representation of thesis 2.3.1: the convex hull of a frame's
// silhouette (all blobs together), with a bit per edge marking edges that lie on the image
// border (the silhouette was clipped there), and the tangent table — the direction of each
// edge, so that vertex i touches every directed tangent line whose direction lies in
// [angle(i-1), angle(i)].
//
// Geometry: pixel coordinates (shared/geometry/conventions.h). A foreground pixel centre lies
// inside the silhouette, whose boundary runs beyond the outermost centres by a gap that
// depends on the direction (shared/silhouette/lattice_boundary.h): the hull from a mask is
// the hull of the foreground centres with each edge moved out by its expected gap, 0.25 to
// 0.5 px, clipped to the image. Vertices are in positive orientation (signed area > 0 in pixel
// coordinates), so edge angles increase around the hull and the silhouette lies to the left of
// every directed edge.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace silnet {

// Hull vertices computed from masks lie on this grid, the wire encoding's resolution (px).
inline constexpr double kHullVertexStep = 1.0 / 16.0;

// Convex hull + clipped-edge bits + tangent table of one silhouette.
class SilhouetteHull {
 public:
  SilhouetteHull() = default;
  // Builds from vertices in positive orientation; `clipped[i]` marks edge i (vertex i to
  // i + 1). Computes the tangent table.
  SilhouetteHull(std::vector<Eigen::Vector2d> vertices, std::vector<bool> clipped);

  bool empty() const { return vertices_.empty(); }
  int size() const { return static_cast<int>(vertices_.size()); }
  const std::vector<Eigen::Vector2d>& vertices() const { return vertices_; }
  const Eigen::Vector2d& vertex(int i) const { return vertices_[static_cast<size_t>(i)]; }
  // Edge i runs from vertex i to vertex (i + 1) mod size().
  bool edge_clipped(int i) const { return clipped_[static_cast<size_t>(i)]; }
  const std::vector<bool>& clipped() const { return clipped_; }
  bool any_clipped() const;
  // Tangent table: direction of edge i in [0, 2 pi).
  double edge_angle(int i) const { return angles_[static_cast<size_t>(i)]; }
  const std::vector<double>& edge_angles() const { return angles_; }
  // True if vertex i lies on a clipped edge (a tangent touching it is not a real one).
  bool vertex_on_clipped_edge(int i) const;
  // Area enclosed by the hull, square pixels.
  double Area() const;
  // True if `point` lies inside or on the hull.
  bool Contains(const Eigen::Vector2d& point) const;

 private:
  std::vector<Eigen::Vector2d> vertices_;
  std::vector<bool> clipped_;
  std::vector<double> angles_;
};

// Statistics of a binary mask gathered with its hull.
struct MaskSummary {
  int foreground_pixels = 0;
  bool touches_border = false;
};

// The silhouette hull of the nonzero pixels of a CV_8UC1 mask: a top-down scan of row
// extents, their hull by monotone chain (linear in the image size), the boundary model, and
// vertices rounded to kHullVertexStep. A dot or a straight run of pixels gets the hull of its
// pixel squares. Edges on the image border,
// x = -0.5, x = width - 0.5, y = -0.5 or y = height - 0.5, are marked clipped. An empty mask
// gives an empty hull. Throws CheckError for a mask of another type.
SilhouetteHull ComputeSilhouetteHull(const cv::Mat& mask, MaskSummary* summary = nullptr);

// Edge angle helper: direction of b - a in [0, 2 pi).
double DirectionAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

}  // namespace silnet
