#pragma once
// The parts of a straight line that lie inside a set of viewing cones (thesis 4.2): the line's
// crossings with the cones' faces, found through ConePlaneSet's epipolar index (a short
// stretch's, the traced edges', through its cell index), ordered along the line and walked by their
// direction (the sign of the face normal along the line tells entering from leaving), so a
// point-in-silhouette test is needed only for a view whose faces the line never crosses. The shared
// step of the hull's viewing edges (viewing_edges.h) and of the cone-intersection edges traced from
// them (hull_edges.h).

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// The points origin + t * direction for t in [lo, hi]; `lo_plane` / `hi_plane` are the cone
// planes that bound it at each end, or -1 where the caller's range does.
struct LineStretch {
  double lo = 0, hi = 0;
  int lo_plane = -1, hi_plane = -1;
};

// A line lying in a cone face plane of view `seen_from` (or through its camera centre): the
// index is asked for the other views' faces in the line's epipolar range about that view.
struct ConeLine {
  int seen_from = -1;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

// `range` of `line` narrowed to the part inside `box` (its end labels kept where the box does
// not cut it, -1 where it does); nullopt if nothing is left.
std::optional<LineStretch> ClipToBox(const ConeLine& line, const WorldBox& box, LineStretch range);

// Per thread: the buffers a line reuses.
struct ConeLineBuffers {
  std::vector<int> candidates;
  struct Crossing {
    double t = 0;
    int plane = -1;
    bool entering = false;
    bool operator<(const Crossing& other) const {
      return t < other.t || (t == other.t && plane < other.plane);
    }
  };
  std::vector<Crossing> crossings;
  std::vector<LineStretch> inside, in_view, both;
};

// The stretches of `range` on `line` inside the cone of every view of `set` but `skip_a` and
// `skip_b` (the views whose planes hold the line), ordered along the line; `centres` are the
// views' camera centres. Generic position assumed: a crossing through a face's contour point
// counts once. The result is left in buffers->inside.
void StretchesInsideCones(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                          const ConeLine& line, const LineStretch& range, int skip_a, int skip_b,
                          ConeLineBuffers* buffers);

// `range` of `line` cut at the first point past range.lo where it leaves the cone of a view
// of `set` other than `skip_a` and `skip_b`, when range.lo lies inside all of them (a vertex
// of the hull the line leaves it from): there the range ends and `hi_plane` is the face
// crossed. Crossings of plane `skip_plane` (the one the line leaves the vertex through) are
// not counted.
LineStretch FirstExit(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                      const ConeLine& line, LineStretch range, int skip_a, int skip_b,
                      int skip_plane, ConeLineBuffers* buffers);

}  // namespace silnet::aggregator
