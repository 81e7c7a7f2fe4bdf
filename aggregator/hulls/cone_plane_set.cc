#include "aggregator/hulls/cone_plane_set.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Height of the point-in-silhouette index's rows, pixels: one pixel keeps a row's edges few
// (4 px rows were 2-3 % slower on the alien set).
constexpr double kRowStepPx = 1.0;
// Margin of the silhouettes' bounding octagons, pixels.
constexpr double kOctagonMarginPx = 1.0;
// Side of the cell index's cells, pixels, and the margin by which an edge's box is grown
// before it is filed in them (far more than the rounding of a crossing's projection). Row
// height and cell side are read as constants where queries divide by them: a power of two
// turns the division into an exact multiplication.
constexpr double kCellPx = 8.0;
constexpr double kCellMarginPx = 0.5;

// The bounding octagon of a view's contour points, grown by the margin.
std::array<Eigen::Vector3d, 8> OctagonAround(const std::vector<ConePlane>& planes,
                                             const std::vector<int>& view_planes) {
  // Directions n of the eight sides; the octagon is n . x <= max over the points.
  const double r = std::sqrt(0.5);
  const std::array<Eigen::Vector2d, 8> directions = {
      Eigen::Vector2d(1, 0),  Eigen::Vector2d(-1, 0), Eigen::Vector2d(0, 1),
      Eigen::Vector2d(0, -1), Eigen::Vector2d(r, r),  Eigen::Vector2d(-r, -r),
      Eigen::Vector2d(r, -r), Eigen::Vector2d(-r, r)};
  std::array<Eigen::Vector3d, 8> sides;
  for (size_t k = 0; k < directions.size(); ++k) {
    double extent = -std::numeric_limits<double>::infinity();
    for (int index : view_planes)
      extent = std::max(extent, directions[k].dot(planes[static_cast<size_t>(index)].p));
    // Inside where extent + margin - n . x >= 0.
    sides[k] = Eigen::Vector3d(-directions[k].x(), -directions[k].y(), extent + kOctagonMarginPx);
  }
  return sides;
}

// Ranges wider than this (pseudo-angle units, 0.8 to 1.6 rad) are not trusted: the edge may
// pass the epipole.
constexpr double kWidestArc = 0.8;

// A stand-in for atan2(y, x) on (-2, 2] with the same order, without trigonometry.
double PseudoAngle(double y, double x) {
  const double sum = std::abs(x) + std::abs(y);
  if (sum == 0) return 0;
  const double p = y / sum;
  if (x >= 0) return p;
  return y >= 0 ? 2 - p : -2 - p;
}

// The offset of contour point `index` of camera `view`: each coordinate uniform in
// [-amplitude, amplitude], a fixed function of the two (splitmix64's finaliser).
Eigen::Vector2d Perturbation(size_t view, size_t index, double amplitude) {
  uint64_t h = (view + 1) * 0x9E3779B97F4A7C15ull ^ (index + 1) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  h ^= h >> 31;
  const auto unit = [](uint64_t bits) { return static_cast<double>(bits) / 0xFFFFFFFFp0; };
  return amplitude * Eigen::Vector2d(2 * unit(h & 0xFFFFFFFFu) - 1, 2 * unit(h >> 32) - 1);
}

}  // namespace

void SortArcs(std::vector<EdgeArc>& arcs, std::vector<EdgeArc>& buffer) {
  const auto before = [](const EdgeArc& x, const EdgeArc& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.plane < y.plane;
  };
  const auto at = [](std::vector<EdgeArc>& v, size_t k) {
    return v.begin() + static_cast<long>(k);
  };
  // Run ends: each run ascending (a strictly descending one reversed in place).
  std::vector<size_t> ends;
  for (size_t begin = 0; begin < arcs.size();) {
    size_t end = begin + 1;
    if (end < arcs.size() && before(arcs[end], arcs[end - 1])) {
      while (end < arcs.size() && before(arcs[end], arcs[end - 1]))
        ++end;
      std::reverse(at(arcs, begin), at(arcs, end));
    } else {
      while (end < arcs.size() && !before(arcs[end], arcs[end - 1]))
        ++end;
    }
    ends.push_back(end);
    begin = end;
  }
  // Neighbouring runs merged pairwise until one is left.
  buffer.resize(arcs.size());
  while (ends.size() > 1) {
    size_t begin = 0, kept = 0;
    for (size_t r = 0; r < ends.size(); r += 2) {
      const size_t middle = ends[r], end = r + 1 < ends.size() ? ends[r + 1] : middle;
      std::merge(at(arcs, begin), at(arcs, middle), at(arcs, middle), at(arcs, end),
                 at(buffer, begin), before);
      ends[kept++] = end;
      begin = end;
    }
    ends.resize(kept);
    arcs.swap(buffer);
  }
}

ConePlaneSet::ConePlaneSet(const std::vector<CameraModel>& cameras,
                           const std::vector<SilhouetteContours>& contours, const WorldBox& bounds,
                           double perturbation_px, int threads) {
  const size_t views = cameras.size();
  view_planes_.resize(views);
  size_t contour_points = 0;
  for (const SilhouetteContours& view : contours)
    contour_points += view.PointCount();
  planes_.reserve(contour_points);
  for (size_t v = 0; v < views; ++v) {
    projections_.push_back(cameras[v].ProjectionMatrix());
    pixel_to_ray_.push_back(cameras[v].R.transpose() * cameras[v].K.inverse());
    view_planes_[v].reserve(contours[v].PointCount());
    const auto add_ring = [&](const std::vector<Eigen::Vector2f>& ring) {
      std::vector<Eigen::Vector2d> points;
      for (const Eigen::Vector2f& point : ring) {
        Eigen::Vector2d x = point.cast<double>();
        if (cameras[v].HasDistortion()) x = cameras[v].UndistortPixel(x);
        if (points.empty() || points.back() != x) points.push_back(x);
      }
      while (points.size() > 1 && points.back() == points.front())
        points.pop_back();
      if (points.size() < 3) return;
      const int first = static_cast<int>(planes_.size());
      if (perturbation_px > 0) {
        for (size_t k = 0; k < points.size(); ++k)
          points[k] += Perturbation(v, static_cast<size_t>(first) + k, perturbation_px);
      }
      const int n = static_cast<int>(points.size());
      for (int k = 0; k < n; ++k) {
        ConePlane plane;
        plane.view = static_cast<int>(v);
        plane.p = points[static_cast<size_t>(k)];
        plane.q = points[static_cast<size_t>((k + 1) % n)];
        plane.prev = first + (k + n - 1) % n;
        plane.next = first + (k + 1) % n;
        view_planes_[v].push_back(static_cast<int>(planes_.size()));
        planes_.push_back(plane);
      }
    };
    for (const ContourPolygon& polygon : contours[v].polygons) {
      add_ring(polygon.outer);
      for (const auto& hole : polygon.holes)
        add_ring(hole);
    }

    RowIndex rows;
    double y_min = std::numeric_limits<double>::infinity(), y_max = -y_min;
    for (int index : view_planes_[v]) {
      y_min = std::min(y_min, Plane(index).p.y());
      y_max = std::max(y_max, Plane(index).p.y());
    }
    if (!view_planes_[v].empty()) {
      rows.y0 = y_min;
      const size_t count = static_cast<size_t>((y_max - y_min) / kRowStepPx) + 1;
      const auto row = [&](double y) {
        return std::clamp(static_cast<size_t>((y - rows.y0) / kRowStepPx), size_t{0}, count - 1);
      };
      const auto row_span = [&](const ConePlane& plane) {
        return std::pair(row(std::min(plane.p.y(), plane.q.y())),
                         row(std::max(plane.p.y(), plane.q.y())));
      };
      rows.starts.assign(count + 1, 0);
      for (int index : view_planes_[v]) {
        const auto [a, b] = row_span(Plane(index));
        for (size_t r = a; r <= b; ++r)
          ++rows.starts[r + 1];
      }
      for (size_t r = 0; r < count; ++r)
        rows.starts[r + 1] += rows.starts[r];
      rows.edges.resize(rows.starts.back());
      std::vector<uint32_t> fill(rows.starts.begin(), rows.starts.end() - 1);
      for (int index : view_planes_[v]) {
        const ConePlane& plane = Plane(index);
        const auto [a, b] = row_span(plane);
        const double dy = plane.q.y() - plane.p.y();
        const RowEdge edge{plane.p.x(), plane.p.y(), plane.q.y(),
                           dy != 0 ? (plane.q.x() - plane.p.x()) / dy : 0.0};
        for (size_t r = a; r <= b; ++r)
          rows.edges[fill[r]++] = edge;
      }
    }
    rows_.push_back(std::move(rows));
    cells_.push_back(BuildCellIndex(planes_, view_planes_[v]));
    octagons_.push_back(OctagonAround(planes_, view_planes_[v]));
  }

  rays_.reserve(planes_.size());
  for (const ConePlane& plane : planes_)
    rays_.push_back(Ray(plane.view, plane.p));
  normals_.reserve(planes_.size());
  for (size_t k = 0; k < planes_.size(); ++k)
    normals_.push_back(rays_[k].cross(rays_[static_cast<size_t>(planes_[k].next)]));

  pairs_.resize(views * views);
  const Eigen::Vector3d centre = bounds.center();
  ParallelFor(views, threads, [&](size_t i) {
    std::vector<double> angles(planes_.size());  // per plane of view j: its ray's angle
    std::vector<EdgeArc> merge_buffer;
    for (size_t j = 0; j < views; ++j) {
      if (i == j) continue;
      PairIndex& pair = pairs_[i * views + j];
      const Eigen::Vector3d b = (cameras[j].Center() - cameras[i].Center()).normalized();
      Eigen::Vector3d toward = centre - cameras[i].Center();
      toward -= toward.dot(b) * b;
      if (toward.norm() < 1e-12) toward = b.unitOrthogonal();
      pair.u1 = toward.normalized();
      pair.u2 = b.cross(pair.u1);
      pair.arcs.reserve(view_planes_[j].size());
      for (int index : view_planes_[j])
        angles[static_cast<size_t>(index)] = Angle(pair, rays_[static_cast<size_t>(index)]);
      for (int index : view_planes_[j]) {
        const double a = angles[static_cast<size_t>(index)];
        const double c = angles[static_cast<size_t>(Plane(index).next)];
        if (std::abs(a - c) > kWidestArc) {
          pair.wide.push_back(index);
          continue;
        }
        pair.arcs.push_back({std::min(a, c), std::max(a, c), index});
      }
      SortArcs(pair.arcs, merge_buffer);
      pair.reach.resize(pair.arcs.size());
      double reach = -std::numeric_limits<double>::infinity();
      for (size_t k = 0; k < pair.arcs.size(); ++k) {
        reach = std::max(reach, pair.arcs[k].hi);
        pair.reach[k] = reach;
      }
    }
  });
}

ConePlaneSet::CellIndex ConePlaneSet::BuildCellIndex(const std::vector<ConePlane>& planes,
                                                     const std::vector<int>& view_planes) {
  CellIndex cells;
  if (view_planes.empty()) return cells;
  Eigen::AlignedBox2d extent;
  for (int index : view_planes)
    extent.extend(planes[static_cast<size_t>(index)].p);
  cells.x0 = extent.min().x() - 2 * kCellMarginPx;
  cells.y0 = extent.min().y() - 2 * kCellMarginPx;
  cells.cols = static_cast<int>((extent.sizes().x() + 4 * kCellMarginPx) / kCellPx) + 1;
  cells.rows = static_cast<int>((extent.sizes().y() + 4 * kCellMarginPx) / kCellPx) + 1;
  // The cells of each edge's box grown by the margin, as column and row ranges.
  const auto span = [&](const ConePlane& plane) {
    const Eigen::Vector2d lo = plane.p.cwiseMin(plane.q).array() - kCellMarginPx;
    const Eigen::Vector2d hi = plane.p.cwiseMax(plane.q).array() + kCellMarginPx;
    const auto cell = [&](double value, double origin, int count) {
      return std::clamp(static_cast<int>((value - origin) / kCellPx), 0, count - 1);
    };
    return std::array<int, 4>{
        cell(lo.x(), cells.x0, cells.cols), cell(hi.x(), cells.x0, cells.cols),
        cell(lo.y(), cells.y0, cells.rows), cell(hi.y(), cells.y0, cells.rows)};
  };
  const auto cols = static_cast<size_t>(cells.cols);
  cells.starts.assign(cols * static_cast<size_t>(cells.rows) + 1, 0);
  const auto for_cells = [&](const ConePlane& plane, const auto& visit) {
    const auto [c0, c1, r0, r1] = span(plane);
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c)
        visit(static_cast<size_t>(r) * cols + static_cast<size_t>(c));
  };
  for (int index : view_planes)
    for_cells(planes[static_cast<size_t>(index)], [&](size_t cell) { ++cells.starts[cell + 1]; });
  for (size_t k = 1; k < cells.starts.size(); ++k)
    cells.starts[k] += cells.starts[k - 1];
  cells.planes.resize(cells.starts.back());
  std::vector<uint32_t> fill(cells.starts.begin(), cells.starts.end() - 1);
  for (int index : view_planes) {
    for_cells(planes[static_cast<size_t>(index)],
              [&](size_t cell) { cells.planes[fill[cell]++] = index; });
  }
  return cells;
}

Eigen::Vector3d ConePlaneSet::Ray(int view, const Eigen::Vector2d& pixel) const {
  return pixel_to_ray_[static_cast<size_t>(view)] * pixel.homogeneous();
}

double ConePlaneSet::Angle(const PairIndex& pair, const Eigen::Vector3d& direction) const {
  return PseudoAngle(direction.dot(pair.u2), direction.dot(pair.u1));
}

bool ConePlaneSet::Contains(int view, const Eigen::Vector2d& x) const {
  const RowIndex& rows = rows_[static_cast<size_t>(view)];
  const double r = (x.y() - rows.y0) / kRowStepPx;  // a constant: no division
  if (!(r >= 0) || r >= static_cast<double>(rows.Rows())) return false;
  const auto row = static_cast<size_t>(r);
  bool inside = false;
  for (uint32_t k = rows.starts[row]; k < rows.starts[row + 1]; ++k) {
    const RowEdge& e = rows.edges[k];
    inside ^= ((e.ay > x.y()) != (e.by > x.y())) & (x.x() < e.dx_dy * (x.y() - e.ay) + e.ax);
  }
  return inside;
}

void ConePlaneSet::CandidateEdges(int view, int other, const Eigen::Vector3d& from,
                                  const Eigen::Vector3d& to, std::vector<int>& out) const {
  const PairIndex& pair = pairs_[static_cast<size_t>(view) * Views() + static_cast<size_t>(other)];
  const double a = Angle(pair, from), c = Angle(pair, to);
  if (std::abs(a - c) > kWidestArc) {
    const auto& all = view_planes_[static_cast<size_t>(other)];
    out.insert(out.end(), all.begin(), all.end());
    return;
  }
  const double lo = std::min(a, c) - 1e-9, hi = std::max(a, c) + 1e-9;
  out.insert(out.end(), pair.wide.begin(), pair.wide.end());
  // The arcs before the first that reaches lo all end before it.
  const auto first = std::lower_bound(pair.reach.begin(), pair.reach.end(), lo);
  for (auto it = pair.arcs.begin() + (first - pair.reach.begin());
       it != pair.arcs.end() && it->lo <= hi; ++it) {
    if (it->hi >= lo) out.push_back(it->plane);
  }
}

bool ConePlaneSet::EdgesNearSegment(int view, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                    size_t max_cells, std::vector<int>& out) const {
  const CellIndex& cells = cells_[static_cast<size_t>(view)];
  if (cells.cols == 0) return true;
  if (!(a.allFinite() && b.allFinite())) return false;
  // In cell units; the segment from the end with the smaller y.
  const Eigen::Vector2d origin(cells.x0, cells.y0);
  Eigen::Vector2d u = (a - origin) / kCellPx, w = (b - origin) / kCellPx;  // by a constant
  if (w.y() < u.y()) std::swap(u, w);
  if (w.y() < 0 || u.y() >= cells.rows) return true;
  // Where the segment is at height y; a horizontal one spans its ends' x at its height.
  const bool level = !(w.y() > u.y());
  const double dx_dy = level ? 0.0 : (w.x() - u.x()) / (w.y() - u.y());
  const auto x_at = [&](double y) { return u.x() + dx_dy * (y - u.y()); };
  // Clamped before the conversion: a point near a camera's plane projects very far.
  const auto index = [](double value, int count) {
    return static_cast<int>(std::clamp(value, 0.0, count - 1.0));
  };
  const int r0 = index(u.y(), cells.rows), r1 = index(w.y(), cells.rows);
  const size_t first = out.size();
  size_t visited = 0;
  // Row by row, the columns of the part of the segment within the row's band.
  for (int r = r0; r <= r1; ++r) {
    const double x_lo = level ? u.x() : x_at(std::max(u.y(), static_cast<double>(r)));
    const double x_hi = level ? w.x() : x_at(std::min(w.y(), static_cast<double>(r + 1)));
    const double left = std::min(x_lo, x_hi), right = std::max(x_lo, x_hi);
    if (right < 0 || left >= cells.cols) continue;
    const int c0 = index(left, cells.cols), c1 = index(right, cells.cols);
    visited += static_cast<size_t>(c1 - c0 + 1);
    if (visited > max_cells) {
      out.resize(first);
      return false;
    }
    const size_t row = static_cast<size_t>(r) * static_cast<size_t>(cells.cols);
    out.insert(out.end(), cells.planes.begin() + cells.starts[row + static_cast<size_t>(c0)],
               cells.planes.begin() + cells.starts[row + static_cast<size_t>(c1) + 1]);
  }
  return true;
}

}  // namespace silnet::aggregator
