#pragma once
// The exact hull's viewing edges (thesis 4.2; the first step of EPVH): for every contour
// vertex of every view, the parts of its viewing ray that lie inside every other view's cone,
// computed once per vertex from ConePlaneSet's epipolar index. The crossings of a ray with
// another view's cone faces are ordered along the ray and walked by the crossing direction
// (the sign of the face normal along the ray tells entering from leaving), so no
// point-in-silhouette test is needed except for a ray that meets no face of a view.
//
// The ends of these edges are the hull's viewing-edge vertices
// (PolyhedralHullStats::viewing_edge_vertices), from which its other edges are traced
// (hull_edges.h).

#include <Eigen/Core>
#include <vector>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// One viewing edge: the points C + t * set.RayThroughP(plane) for t in [near, far], where C
// is the view's camera centre, along the ray through the first point of cone plane `plane` (a
// contour vertex of `view`). `near_plane` / `far_plane` are the other views' cone planes that
// bound it at each end, or -1 where the bounds box does.
struct ViewingEdge {
  int plane = -1;
  int view = -1;
  double near = 0, far = 0;
  int near_plane = -1, far_plane = -1;
};

// The viewing edges of every contour vertex of `set` (built from `cameras`, in the same
// order) inside `bounds`, ordered by plane and then by depth, on `threads` threads (the result
// does not depend on their number). Assumes generic position, as the hull's faces do: a ray
// through another view's contour vertex or along a face counts as crossing it at most once.
std::vector<ViewingEdge> ComputeViewingEdges(const std::vector<CameraModel>& cameras,
                                             const ConePlaneSet& set, const WorldBox& bounds,
                                             int threads = 1);

// The world point at depth `t` on `edge`'s ray.
Eigen::Vector3d ViewingEdgePoint(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                                 const ViewingEdge& edge, double t);

}  // namespace silnet::aggregator
