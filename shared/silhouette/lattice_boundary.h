#pragma once
// Where a silhouette's boundary lies around the hull of its foreground pixel centres.
//
// A pixel is foreground when its centre falls inside the silhouette, so the boundary runs
// beyond the outermost centres by a gap that depends on the direction. Every edge of the hull
// of centres joins two lattice points, so it runs along a lattice direction (p, q) (reduced
// integers) whose lattice lines are 1 / |(p, q)| apart: a boundary parallel to it lies a
// uniform fraction of that spacing beyond the edge, half of it on average (0.5 px for rows
// and columns, 0.35 px for diagonals). Between such directions the gap is set by the
// boundary's curvature, about 0.25 px for silhouettes whose outline bends over 5-50 pixels.
// The boundary polygon is the hull's edges each moved outward by its expected gap.

#include <Eigen/Core>
#include <vector>

namespace silnet {

// The expected gap, pixels, between an edge of the hull of pixel centres running along
// `edge` (a difference of two pixel centres, integer components, not zero) and the boundary.
double ExpectedBoundaryGap(const Eigen::Vector2d& edge);

// The intersection of the half-planes of `centres`' edges (a convex polygon of pixel centres
// in positive orientation, at least three vertices), each moved outward by its expected gap,
// and of the image rectangle [-0.5, width - 0.5] x [-0.5, height - 0.5]. Corners sharper
// than a right angle are bevelled, the bevel the larger of the two gaps beyond the corner.
// Positive orientation; empty if the polygon degenerates.
std::vector<Eigen::Vector2d> LatticeBoundaryPolygon(const std::vector<Eigen::Vector2d>& centres,
                                                    int width, int height);

}  // namespace silnet
