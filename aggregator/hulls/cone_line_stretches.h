#pragma once
// The parts of a straight line that lie inside a set of viewing cones (thesis 4.2): the line's
// crossings with the cones' faces, found through ConePlaneSet's epipolar index, ordered along
// the line and walked by their direction (the sign of the face normal along the line tells
// entering from leaving), so a point-in-silhouette test is needed only for a view whose faces
// the line never crosses. The shared step of the hull's viewing edges (viewing_edges.h) and
// of the cone-intersection edges traced from them (hull_edges.h).

#include <Eigen/Core>
#include <limits>
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
// `inside_at`, where known, is a parameter at which the line lies inside every cone (a vertex
// of the hull): a view whose faces the line does not cross around it then holds the line
// without a point-in-silhouette test.
struct ConeLine {
  int seen_from = -1;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double inside_at = std::numeric_limits<double>::quiet_NaN();
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

}  // namespace silnet::aggregator
