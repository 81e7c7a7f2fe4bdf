#include "aggregator/hulls/viewing_edges.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// A stretch [lo, hi] of a ray's depth with the planes bounding it (-1: the bounds box).
struct Stretch {
  double lo = 0, hi = 0;
  int lo_plane = -1, hi_plane = -1;
};

// Where a ray crosses one of another view's cone faces: its depth, the face, and whether the
// ray enters that view's cone there.
struct Crossing {
  double t = 0;
  int plane = -1;
  bool entering = false;

  bool operator<(const Crossing& other) const {
    return t < other.t || (t == other.t && plane < other.plane);
  }
};

// The depths at which the ray from `centre` along `direction` lies inside `box`; nullopt if
// it misses it.
std::optional<Stretch> ClipToBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& direction,
                                 const WorldBox& box) {
  Stretch s{0.0, std::numeric_limits<double>::infinity()};
  for (int a = 0; a < 3; ++a) {
    if (direction[a] == 0.0) {
      if (centre[a] < box.min()[a] || centre[a] > box.max()[a]) return std::nullopt;
      continue;
    }
    double t1 = (box.min()[a] - centre[a]) / direction[a];
    double t2 = (box.max()[a] - centre[a]) / direction[a];
    if (t1 > t2) std::swap(t1, t2);
    s.lo = std::max(s.lo, t1);
    s.hi = std::min(s.hi, t2);
  }
  if (!(s.hi > s.lo)) return std::nullopt;
  return s;
}

// Per thread: the buffers one ray reuses.
struct RayBuffers {
  std::vector<int> candidates;
  std::vector<Crossing> crossings;
  std::vector<Stretch> inside, in_view, both;
};

// The crossings within `range` of the ray (centre, direction) with view `other`'s cone faces
// that the epipolar index offers for view `view`'s ray, sorted by depth.
void FindCrossings(const ConePlaneSet& set, int view, int other, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& other_centre, const Eigen::Vector3d& direction,
                   const Stretch& range, RayBuffers* buffers) {
  buffers->candidates.clear();
  buffers->crossings.clear();
  set.CandidateEdges(view, other, direction, direction, buffers->candidates);
  const Matrix34d& projection = set.Projection(other);
  for (const int q : buffers->candidates) {
    const Eigen::Vector3d& normal = set.Normal(q);
    const double along = normal.dot(direction);
    if (along == 0.0) continue;
    const double t = normal.dot(other_centre - centre) / along;
    if (!(t > range.lo && t < range.hi)) continue;
    // The plane holds the whole line through the other camera's centre: the crossing is on
    // the face if it projects between the face's contour points.
    const Eigen::Vector3d x = projection * (centre + t * direction).homogeneous();
    if (!(x.z() > 0)) continue;
    const ConePlane& face = set.Plane(q);
    const Eigen::Vector2d edge = face.q - face.p;
    const double s = (x.hnormalized() - face.p).dot(edge) / edge.squaredNorm();
    if (s < 0.0 || s >= 1.0) continue;
    buffers->crossings.push_back({t, q, along > 0.0});
  }
  std::sort(buffers->crossings.begin(), buffers->crossings.end());
}

// The stretches of `range` inside view `other`'s cone, from the sorted crossings (a ray with
// none is inside throughout or not at all: one point-in-silhouette test decides).
void InsideStretches(const ConePlaneSet& set, int other, const Eigen::Vector3d& centre,
                     const Eigen::Vector3d& direction, const Stretch& range, RayBuffers* buffers) {
  std::vector<Stretch>& out = buffers->in_view;
  out.clear();
  const std::vector<Crossing>& crossings = buffers->crossings;
  bool inside = false;
  if (crossings.empty()) {
    const Eigen::Vector3d x =
        set.Projection(other) * (centre + 0.5 * (range.lo + range.hi) * direction).homogeneous();
    inside = x.z() > 0 && set.Contains(other, x.hnormalized());
  } else {
    inside = !crossings.front().entering;
  }
  Stretch open{range.lo, range.hi, range.lo_plane, range.hi_plane};
  for (const Crossing& c : crossings) {
    if (c.entering) {
      open.lo = c.t;
      open.lo_plane = c.plane;
      inside = true;
    } else {
      if (inside) out.push_back({open.lo, c.t, open.lo_plane, c.plane});
      inside = false;
    }
  }
  if (inside) out.push_back({open.lo, range.hi, open.lo_plane, range.hi_plane});
}

// buffers->inside narrowed to its overlap with buffers->in_view.
void Intersect(RayBuffers* buffers) {
  const std::vector<Stretch>& a = buffers->inside;
  const std::vector<Stretch>& b = buffers->in_view;
  std::vector<Stretch>& out = buffers->both;
  out.clear();
  for (size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    const Stretch& s = a[i];
    const Stretch& u = b[j];
    Stretch both = s;
    if (u.lo > both.lo) {
      both.lo = u.lo;
      both.lo_plane = u.lo_plane;
    }
    if (u.hi < both.hi) {
      both.hi = u.hi;
      both.hi_plane = u.hi_plane;
    }
    if (both.hi > both.lo) out.push_back(both);
    if (s.hi < u.hi) {
      ++i;
    } else {
      ++j;
    }
  }
  std::swap(buffers->inside, out);
}

// The viewing edges of the contour vertex that starts cone plane `plane`.
void RayEdges(const std::vector<Eigen::Vector3d>& centres, const ConePlaneSet& set,
              const WorldBox& bounds, int plane, RayBuffers* buffers,
              std::vector<ViewingEdge>* out) {
  const ConePlane& face = set.Plane(plane);
  const Eigen::Vector3d& centre = centres[static_cast<size_t>(face.view)];
  const Eigen::Vector3d direction = set.Ray(face.view, face.p);
  const std::optional<Stretch> range = ClipToBox(centre, direction, bounds);
  if (!range) return;
  buffers->inside.assign(1, *range);
  const int views = static_cast<int>(set.Views());
  for (int other = 0; other < views && !buffers->inside.empty(); ++other) {
    if (other == face.view) continue;
    const Stretch within{buffers->inside.front().lo, buffers->inside.back().hi, -1, -1};
    FindCrossings(set, face.view, other, centre, centres[static_cast<size_t>(other)], direction,
                  within, buffers);
    InsideStretches(set, other, centre, direction, within, buffers);
    Intersect(buffers);
  }
  for (const Stretch& s : buffers->inside)
    out->push_back({plane, face.view, s.lo, s.hi, s.lo_plane, s.hi_plane});
}

}  // namespace

std::vector<ViewingEdge> ComputeViewingEdges(const std::vector<CameraModel>& cameras,
                                             const ConePlaneSet& set, const WorldBox& bounds,
                                             int threads) {
  SILNET_CHECK(cameras.size() == set.Views());
  std::vector<Eigen::Vector3d> centres;
  for (const CameraModel& camera : cameras)
    centres.push_back(camera.Center());
  // Rays in chunks of consecutive planes, concatenated in plane order afterwards.
  const size_t planes = set.Planes().size();
  const size_t chunk = 256;
  const size_t chunks = (planes + chunk - 1) / chunk;
  std::vector<std::vector<ViewingEdge>> parts(chunks);
  ParallelFor(chunks, threads, [&](size_t k) {
    RayBuffers buffers;
    const size_t end = std::min(planes, (k + 1) * chunk);
    for (size_t p = k * chunk; p < end; ++p)
      RayEdges(centres, set, bounds, static_cast<int>(p), &buffers, &parts[k]);
  });
  std::vector<ViewingEdge> edges;
  for (const std::vector<ViewingEdge>& part : parts)
    edges.insert(edges.end(), part.begin(), part.end());
  return edges;
}

Eigen::Vector3d ViewingEdgePoint(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                                 const ViewingEdge& edge, double t) {
  const ConePlane& face = set.Plane(edge.plane);
  return cameras[static_cast<size_t>(edge.view)].Center() + t * set.Ray(edge.view, face.p);
}

}  // namespace silnet::aggregator
