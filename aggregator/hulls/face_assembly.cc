#include "aggregator/hulls/face_assembly.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "aggregator/hulls/face_boundary_loops.h"
#include "aggregator/hulls/loop_triangulation.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// A corner is at an event if their w differ by less than this fraction of the chart's range.
constexpr double kEventTolerance = 1e-7;

// A hull vertex named by what meets there: three planes (sorted, a < b < c), or a cut that
// face `a`'s sweep made on its edge with plane `b` at its slab boundary -c - 1.
struct VertexKey {
  int a, b, c;
  bool operator==(const VertexKey&) const = default;
};

struct VertexKeyHash {
  size_t operator()(const VertexKey& k) const {
    size_t h = static_cast<size_t>(k.a) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<size_t>(k.b) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= static_cast<size_t>(static_cast<unsigned>(k.c)) + 0x94D049BB133111EBull + (h << 6) +
         (h >> 2);
    return h;
  }
};

VertexKey Triple(int a, int b, int c) {
  std::array<int, 3> s = {a, b, c};
  std::sort(s.begin(), s.end());
  return {s[0], s[1], s[2]};
}

uint64_t EdgeKey(int owner, int line) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(owner)) << 32) | static_cast<uint32_t>(line);
}

// A corner on one of a face's slab boundaries.
struct BoundaryCorner {
  double lambda = 0;
  Corner corner;
};

// A corner a face's first pass named: its name (the planes that meet there), where it lies in
// the face's chart, and the hull vertex it becomes once the names are registered.
struct NamedCorner {
  VertexKey key;
  double lambda, w;
  int vertex = -1;
};

// A face after the first pass: its trapezoids and the corners on its slab boundaries,
// sorted by lambda, then w (with cuts). Without cuts, the trapezoids' corners refer to `named`
// (index >= 0) or are the face's cuts (-1, -2, ... in order) until the names are registered;
// the second pass leaves the face's triangles, the positions of its sliver cuts (a triangle's
// vertex -k - 1 is the k-th) and whether the face is on the hull.
struct FaceCorners {
  std::vector<Trapezoid> trapezoids;
  std::vector<BoundaryCorner> boundary;
  std::vector<NamedCorner> named;
  int cuts = 0, cut_base = 0;  // the face's cuts, and how many the faces before it have
  std::vector<std::array<int32_t, 3>> triangles;
  std::vector<Eigen::Vector3d> slivers;
  bool on_hull = false;
};

// Buffers the second pass of a face reuses (one set per thread).
struct PolygonScratch {
  std::vector<std::vector<LoopPoint>> loops;
  std::vector<std::vector<Eigen::Vector2d>> chart_loops;
  std::vector<int> loop_vertices;
};

// A point of a face's polygon in its chart.
struct ChartVertex {
  double lambda, w;
  int vertex;
};

double Cross(const ChartVertex& o, const ChartVertex& a, const ChartVertex& b) {
  return (a.lambda - o.lambda) * (b.w - o.w) - (a.w - o.w) * (b.lambda - o.lambda);
}

// Triangulates a convex chart polygon (counter-clockwise). Points on its sides (collinear
// with their neighbours) are kept as vertices, since the neighbouring face has them too: the
// polygon is then fanned from a new vertex at its centroid (which `add_vertex` creates),
// otherwise from its first vertex.
template <typename AddVertex>
void TriangulateConvex(const std::vector<ChartVertex>& polygon, bool reverse, AddVertex add_vertex,
                       std::vector<std::array<int32_t, 3>>& triangles) {
  const size_t n = polygon.size();
  if (n < 3) return;
  const auto emit = [&](int a, int b, int c) {
    triangles.push_back(reverse ? std::array<int32_t, 3>{a, c, b}
                                : std::array<int32_t, 3>{a, b, c});
  };
  bool collinear = false;
  double area = 0, lambda = 0, w = 0;
  for (size_t k = 0; k < n; ++k) {
    const ChartVertex& prev = polygon[(k + n - 1) % n];
    const ChartVertex& next = polygon[(k + 1) % n];
    // Collinear when the turn's sine is below 1e-9 (compared squared, without roots).
    const double cross = Cross(prev, polygon[k], next);
    const double in_lambda = polygon[k].lambda - prev.lambda, in_w = polygon[k].w - prev.w;
    const double out_lambda = next.lambda - polygon[k].lambda, out_w = next.w - polygon[k].w;
    const double lengths_squared =
        (in_lambda * in_lambda + in_w * in_w) * (out_lambda * out_lambda + out_w * out_w);
    if (cross <= 0 || cross * cross <= 1e-18 * lengths_squared) collinear = true;
    area += Cross(polygon[0], polygon[k], next);
    lambda += polygon[k].lambda;
    w += polygon[k].w;
  }
  if (!(area > 0)) return;  // degenerate: no interior
  if (!collinear) {
    for (size_t k = 1; k + 1 < n; ++k)
      emit(polygon[0].vertex, polygon[k].vertex, polygon[k + 1].vertex);
    return;
  }
  const int centre = add_vertex(lambda / static_cast<double>(n), w / static_cast<double>(n));
  for (size_t k = 0; k < n; ++k)
    emit(centre, polygon[k].vertex, polygon[(k + 1) % n].vertex);
}

// Merges the named vertices (on two or more of their `planes`, not a polygon's own centre)
// closer than `tolerance` (where more than three cone faces meet, the faces name the point by
// different triples), drops the triangles that collapse and the vertices no triangle uses.
// `mesh_index` gets each position's mesh vertex, or -1.
TriangleMesh WeldCoincidentVertices(const std::vector<Eigen::Vector3d>& positions,
                                    const std::vector<std::array<int, 3>>& planes,
                                    const std::vector<std::array<int32_t, 3>>& triangles,
                                    double tolerance, std::vector<int>& mesh_index) {
  std::vector<int> order;
  for (size_t v = 0; v < positions.size(); ++v) {
    if (planes[v][1] >= 0) order.push_back(static_cast<int>(v));
  }
  std::sort(order.begin(), order.end(), [&](int x, int y) {
    return positions[static_cast<size_t>(x)].x() < positions[static_cast<size_t>(y)].x();
  });
  std::vector<int> target(positions.size());
  for (size_t v = 0; v < target.size(); ++v)
    target[v] = static_cast<int>(v);
  for (size_t k = 0; k < order.size(); ++k) {
    const Eigen::Vector3d& x = positions[static_cast<size_t>(order[k])];
    for (size_t m = k; m-- > 0;) {
      const Eigen::Vector3d& y = positions[static_cast<size_t>(order[m])];
      if (x.x() - y.x() > tolerance) break;
      if ((x - y).norm() <= tolerance) {
        target[static_cast<size_t>(order[k])] = target[static_cast<size_t>(order[m])];
        break;
      }
    }
  }
  TriangleMesh mesh;
  std::vector<int> index(positions.size(), -1);
  mesh_index.resize(positions.size());
  for (const auto& t : triangles) {
    std::array<int32_t, 3> m;
    for (size_t k = 0; k < 3; ++k) {
      const size_t v = static_cast<size_t>(target[static_cast<size_t>(t[k])]);
      if (index[v] < 0) {
        index[v] = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(positions[v].cast<float>());
      }
      m[k] = index[v];
    }
    if (m[0] != m[1] && m[1] != m[2] && m[0] != m[2]) mesh.triangles.push_back(m);
  }
  for (size_t v = 0; v < positions.size(); ++v)
    mesh_index[v] = index[static_cast<size_t>(target[v])];
  return mesh;
}

// Assembles the mesh from the faces' regions (two passes: corners, then polygons).
class HullAssembler {
 public:
  explicit HullAssembler(const ConePlaneSet& set) : set_(set), faces_(set.Planes().size()) {
    ids_.reserve(8 * set.Planes().size());
  }

  // Pass one with the cuts: names the corners of every trapezoid of `region`, the sweep's cuts
  // (corners where no planes meet) included, and keeps the corners on its slab boundaries.
  void AddCorners(const FaceRegion& region) {
    FaceCorners& face = faces_[static_cast<size_t>(region.plane)];
    const ConePlane& plane = set_.Plane(region.plane);
    WalkTrapezoids(region, face, [&](int line, double lambda, double w, int boundary) {
      const std::optional<VertexKey> named = CornerKey(region, plane, line, lambda, w);
      const VertexKey key = named ? *named : VertexKey{region.plane, line, -boundary - 1};
      const auto [vertex, added] = Vertex(key, !named, region, lambda, w);
      if (added && !named) cuts_.emplace_back(EdgeKey(region.plane, line), vertex);
      const Corner c{w, vertex};
      face.boundary.push_back({lambda, c});
      return c;
    });
    std::sort(face.boundary.begin(), face.boundary.end(),
              [](const BoundaryCorner& x, const BoundaryCorner& y) {
                return x.lambda < y.lambda || (x.lambda == y.lambda && x.corner.w < y.corner.w);
              });
  }

  // Ends pass one with the cuts: indexes the cuts the faces made on their edges.
  void IndexCuts() { std::sort(cuts_.begin(), cuts_.end()); }

  // Both passes with the hull's own vertices only, over `regions` (every face, in plane
  // order), each face's own work on `threads` threads (the mesh does not depend on their
  // number): every face triangulated as the polygon it really is (its trapezoids' boundary
  // without the sweep's cuts). False when some face's boundary is not closed loops of named
  // vertices or does not triangulate (a near-degenerate face); the caller then assembles every
  // face with the cuts instead, in a new assembler (AddCorners, IndexCuts, AddTriangles).
  bool AddFacePolygons(const std::vector<FaceRegion>& regions, int threads) {
    ParallelFor(regions.size(), threads, [&](size_t p) { NameCorners(regions[p]); });
    for (const FaceRegion& region : regions)
      RegisterNames(region);
    std::atomic<bool> triangulated{true};
    ParallelFor(regions.size(), threads, [&](size_t p) {
      if (!TriangulateFace(regions[p])) triangulated = false;
    });
    if (!triangulated) return false;
    for (const FaceRegion& region : regions)
      AppendFace(region);
    return true;
  }

  // Pass two with the cuts: triangulates every trapezoid of `region`, its edges split wherever
  // the neighbouring faces have corners on them.
  void AddTriangles(const FaceRegion& region) {
    const FaceCorners& face = faces_[static_cast<size_t>(region.plane)];
    if (face.trapezoids.empty()) return;
    ++stats_.hull_faces;
    const ConePlane& plane = set_.Plane(region.plane);
    const bool reverse = !ChartIsOutward(region, plane);
    for (const Trapezoid& t : face.trapezoids) {
      polygon_.clear();
      const auto push = [&](double lambda, double w, int vertex) {
        if (polygon_.empty() || polygon_.back().vertex != vertex)
          polygon_.push_back({lambda, w, vertex});
      };
      const auto push_side = [&](double lambda, const Corner& low, const Corner& high, bool down) {
        SideCuts(face, lambda, low, high, down, side_);
        for (const Corner& c : side_)
          push(lambda, c.w, c.vertex);
      };
      const auto push_edge = [&](int line, bool top) {
        EdgeCuts(region, face, plane, line, t, top, edge_);
        for (const ChartVertex& x : edge_)
          push(x.lambda, x.w, x.vertex);
      };
      push(t.a, t.bottom_a.w, t.bottom_a.vertex);
      push_edge(t.lo, false);
      push(t.b, t.bottom_b.w, t.bottom_b.vertex);
      push_side(t.b, t.bottom_b, t.top_b, false);
      push(t.b, t.top_b.w, t.top_b.vertex);
      push_edge(t.hi, true);
      push(t.a, t.top_a.w, t.top_a.vertex);
      push_side(t.a, t.bottom_a, t.top_a, true);
      if (polygon_.size() > 1 && polygon_.back().vertex == polygon_.front().vertex)
        polygon_.pop_back();
      const auto add_vertex = [&](double lambda, double w) {
        positions_.push_back(region.Point(lambda, w));
        planes_.push_back({region.plane, -1, -1});  // a polygon's own centre: only this face
        return static_cast<int>(positions_.size()) - 1;
      };
      TriangulateConvex(polygon_, reverse, add_vertex, triangles_);
    }
  }

  // The mesh, with vertices closer than `tolerance` merged.
  TriangleMesh Mesh(double tolerance) {
    return WeldCoincidentVertices(positions_, planes_, triangles_, tolerance, mesh_index_);
  }

  // The sorted cone planes each of the last mesh's `count` vertices lies on (all its names').
  std::vector<std::vector<int>> MeshVertexPlanes(size_t count) const {
    std::vector<std::vector<int>> planes(count);
    for (size_t v = 0; v < positions_.size(); ++v) {
      if (mesh_index_[v] < 0) continue;
      std::vector<int>& list = planes[static_cast<size_t>(mesh_index_[v])];
      for (const int plane : planes_[v]) {
        if (plane >= 0) list.push_back(plane);
      }
    }
    for (std::vector<int>& list : planes) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }
    return planes;
  }
  const PolyhedralHullStats& Stats() const { return stats_; }

 private:
  // Walks `region`'s trapezoids slab by slab into face.trapezoids, each corner from
  // name(plane of its line, lambda, w, slab boundary). Corners on the boundary between two slabs
  // are named once: the next slab's a-side corners are the previous slab's b-side ones on the same
  // line.
  template <typename Name>
  static void WalkTrapezoids(const FaceRegion& region, FaceCorners& face, Name name) {
    thread_local std::vector<std::pair<int, Corner>> previous, current;
    previous.clear();
    face.trapezoids.reserve(region.intervals.size());  // one per slab's interval
    for (size_t s = 0; s < region.slabs.size(); ++s) {
      const ChartSlab& slab = region.slabs[s];
      current.clear();
      const auto corner = [&](int line, double lambda, int boundary) {
        const ChartLine& chart_line = region.lines[static_cast<size_t>(line)];
        return name(chart_line.plane, lambda, chart_line.WAt(lambda), boundary);
      };
      const auto a_corner = [&](int line) {
        for (const auto& [known, c] : previous) {
          if (known == line) return c;  // slabs are contiguous: this is the same point
        }
        return corner(line, slab.lambda_a, static_cast<int>(s));
      };
      for (int i = slab.first; i < slab.first + slab.count; ++i) {
        const auto [lo, hi] = region.intervals[static_cast<size_t>(i)];
        Trapezoid t;
        t.lo = lo;
        t.hi = hi;
        t.a = slab.lambda_a;
        t.b = slab.lambda_b;
        t.bottom_a = a_corner(lo);
        t.top_a = a_corner(hi);
        t.bottom_b = corner(lo, t.b, static_cast<int>(s) + 1);
        t.top_b = corner(hi, t.b, static_cast<int>(s) + 1);
        current.emplace_back(lo, t.bottom_b);
        current.emplace_back(hi, t.top_b);
        face.trapezoids.push_back(t);
      }
      previous.swap(current);
    }
  }

  // The name of the corner at (lambda, w) of `region` on the line of plane `line`: the three
  // planes that meet there (the face's, the line's, and the ray's or the event's), or none for
  // a cut.
  static std::optional<VertexKey> CornerKey(const FaceRegion& region, const ConePlane& plane,
                                            int line, double lambda, double w) {
    if (lambda == 0) return Triple(region.plane, plane.prev, line);
    if (lambda == 1) return Triple(region.plane, plane.next, line);
    const auto first =
        std::lower_bound(region.events.begin(), region.events.end(), lambda,
                         [](const ChartEvent& e, double value) { return e.lambda < value; });
    for (auto e = first; e != region.events.end() && e->lambda == lambda; ++e) {
      if (e->second >= 0 && (e->first == line || e->second == line) &&
          std::abs(e->w - w) <= kEventTolerance * (region.w_max - region.w_min)) {
        return Triple(region.plane, e->first, e->second);
      }
    }
    return std::nullopt;
  }

  // The hull vertex named `key` (a cut, on the face and its line only, if `cut`), placed at
  // (lambda, w) of `region`'s chart if the name is new; whether it is.
  std::pair<int, bool> Vertex(const VertexKey& key, bool cut, const FaceRegion& region,
                              double lambda, double w) {
    const auto [it, inserted] = ids_.try_emplace(key, static_cast<int>(positions_.size()));
    if (inserted) {
      positions_.push_back(region.Point(lambda, w));
      planes_.push_back({key.a, key.b, cut ? -1 : key.c});
      Count(key);
    }
    return {it->second, inserted};
  }

  // Pass one without the cuts, on any thread: the face's trapezoids, their corners referring
  // to face.named or numbered as the face's cuts (FaceCorners).
  void NameCorners(const FaceRegion& region) {
    FaceCorners& face = faces_[static_cast<size_t>(region.plane)];
    const ConePlane& plane = set_.Plane(region.plane);
    face.named.reserve(2 * region.intervals.size() + 2);  // each trapezoid's right corners
    WalkTrapezoids(region, face, [&](int line, double lambda, double w, int) {
      const std::optional<VertexKey> key = CornerKey(region, plane, line, lambda, w);
      if (!key) return Corner{w, -++face.cuts};
      face.named.push_back({*key, lambda, w});
      return Corner{w, static_cast<int>(face.named.size()) - 1};
    });
  }

  // Ends pass one without the cuts, faces in plane order: each named corner gets its hull
  // vertex (placed by the first face that names it), the face's cuts numbers after the
  // previous faces'.
  void RegisterNames(const FaceRegion& region) {
    FaceCorners& face = faces_[static_cast<size_t>(region.plane)];
    for (NamedCorner& corner : face.named)
      corner.vertex = Vertex(corner.key, false, region, corner.lambda, corner.w).first;
    face.cut_base = registered_cuts_;
    registered_cuts_ += face.cuts;
  }

  // Pass two without the cuts, on any thread: the face's corners made hull vertices (a cut a
  // negative number no other corner has), the polygon the face really is triangulated into
  // face.triangles. False as AddFacePolygons.
  bool TriangulateFace(const FaceRegion& region) {
    FaceCorners& face = faces_[static_cast<size_t>(region.plane)];
    if (face.trapezoids.empty()) return true;
    for (Trapezoid& t : face.trapezoids) {
      for (Corner* c : {&t.bottom_a, &t.bottom_b, &t.top_a, &t.top_b}) {
        c->vertex = c->vertex >= 0 ? face.named[static_cast<size_t>(c->vertex)].vertex
                                   : c->vertex - 1 - face.cut_base;
      }
    }
    thread_local PolygonScratch scratch;
    if (!FaceBoundaryLoops(face.trapezoids, region.w_max - region.w_min, scratch.loops))
      return false;
    if (scratch.loops.empty()) return true;  // a sliver without area
    const double w_scale = 1 / (region.w_max - region.w_min);
    scratch.chart_loops.resize(scratch.loops.size());
    scratch.loop_vertices.clear();
    for (size_t k = 0; k < scratch.loops.size(); ++k) {
      scratch.chart_loops[k].clear();
      for (const LoopPoint& point : scratch.loops[k]) {
        scratch.chart_loops[k].emplace_back(point.lambda, (point.w - region.w_min) * w_scale);
        if (point.vertex >= 0) {
          scratch.loop_vertices.push_back(point.vertex);
          continue;
        }
        // A cut the boundary keeps (at a sliver of a slab, face_boundary_loops.h): on this
        // face and one of its lines, so welding merges it with the named vertex it all but
        // coincides with.
        face.slivers.push_back(region.Point(point.lambda, point.w));
        scratch.loop_vertices.push_back(-static_cast<int>(face.slivers.size()));
      }
    }
    const LoopTriangulation triangulation = TriangulateLoops(scratch.chart_loops);
    if (!triangulation.success) return false;
    face.on_hull = true;
    const bool reverse = !ChartIsOutward(region, set_.Plane(region.plane));
    face.triangles.reserve(triangulation.triangles.size());
    for (const auto& t : triangulation.triangles) {
      const auto vertex = [&](int k) {
        return scratch.loop_vertices[static_cast<size_t>(t[static_cast<size_t>(k)])];
      };
      face.triangles.push_back(reverse ? std::array<int32_t, 3>{vertex(0), vertex(2), vertex(1)}
                                       : std::array<int32_t, 3>{vertex(0), vertex(1), vertex(2)});
    }
    return true;
  }

  // Ends pass two without the cuts, faces in plane order: the face's sliver cuts and
  // triangles added to the mesh.
  void AppendFace(const FaceRegion& region) {
    FaceCorners& face = faces_[static_cast<size_t>(region.plane)];
    const int base = static_cast<int>(positions_.size());
    for (const Eigen::Vector3d& x : face.slivers) {
      positions_.push_back(x);
      planes_.push_back({region.plane, region.plane, -1});
    }
    for (std::array<int32_t, 3> t : face.triangles) {
      for (int32_t& v : t) {
        if (v < 0) v = base - v - 1;
      }
      triangles_.push_back(t);
    }
    if (face.on_hull) ++stats_.hull_faces;
  }

  void Count(const VertexKey& key) {
    if (key.c < 0) {
      ++stats_.edge_points;
      return;
    }
    const int va = set_.Plane(key.a).view;
    const int vb = set_.Plane(key.b).view;
    const int vc = set_.Plane(key.c).view;
    if (va != vb && vb != vc && va != vc) {
      ++stats_.triple_points;
    } else {
      ++stats_.viewing_edge_vertices;
    }
  }

  // The cuts the face of line `line_index` made on its edge with this face that belong to
  // trapezoid `t`'s side along that line, in polygon order (from the a-end to the b-end below,
  // back above), into `out`. Both faces of the edge place its points by one parameter, the
  // position along the planes' common direction, so they agree on the order even where the
  // planes are nearly parallel and their charts disagree. A cut belongs to the side whose
  // span contains it or, where rounding puts it outside every span of the line, the nearest.
  void EdgeCuts(const FaceRegion& region, const FaceCorners& face, const ConePlane& plane,
                int line_index, const Trapezoid& t, bool top, std::vector<ChartVertex>& out) const {
    out.clear();
    const ChartLine& line = region.lines[static_cast<size_t>(line_index)];
    const uint64_t key = EdgeKey(line.plane, region.plane);
    auto it = std::lower_bound(cuts_.begin(), cuts_.end(), std::pair<uint64_t, int>(key, -1));
    if (it == cuts_.end() || it->first != key) return;
    const Eigen::Vector3d direction = EdgeDirection(region.plane, line.plane);
    const auto along = [&](int vertex) {
      return direction.dot(positions_[static_cast<size_t>(vertex)]);
    };
    // The span of trapezoid u's side on the line: parameters at its a- and b-ends.
    const auto span = [&](const Trapezoid& u) {
      const bool upper = u.hi == line_index;
      return std::pair<double, double>(along(upper ? u.top_a.vertex : u.bottom_a.vertex),
                                       along(upper ? u.top_b.vertex : u.bottom_b.vertex));
    };
    const auto distance = [](double x, const std::pair<double, double>& ends) {
      const double low = std::min(ends.first, ends.second);
      const double high = std::max(ends.first, ends.second);
      return x < low ? low - x : (x > high ? x - high : 0.0);
    };
    const auto mine = span(t);
    // Polygon order runs from the side's first corner to its last.
    const double sign = (top ? mine.first - mine.second : mine.second - mine.first) >= 0 ? 1 : -1;
    const Matrix34d& P = set_.Projection(plane.view);
    const Eigen::Vector2d edge = plane.q - plane.p;
    ordered_cuts_.clear();
    for (; it != cuts_.end() && it->first == key; ++it) {
      const double x = along(it->second);
      const double gap = distance(x, mine);
      bool ours = gap == 0 && x != mine.first && x != mine.second;
      if (gap > 0) {
        ours = true;
        for (const Trapezoid& u : face.trapezoids) {
          if (&u != &t && (u.lo == line_index || u.hi == line_index) &&
              distance(x, span(u)) <= gap) {
            ours = false;
            break;
          }
        }
      }
      if (!ours) continue;
      const Eigen::Vector2d pixel =
          (P * positions_[static_cast<size_t>(it->second)].homogeneous()).hnormalized();
      const double lambda = (pixel - plane.p).dot(edge) / edge.squaredNorm();
      ordered_cuts_.push_back({sign * x, ChartVertex{lambda, line.WAt(lambda), it->second}});
    }
    std::sort(ordered_cuts_.begin(), ordered_cuts_.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    for (const auto& cut : ordered_cuts_)
      out.push_back(cut.second);
  }

  // The unit direction of the line where planes `a` and `b` meet, the same for either order.
  Eigen::Vector3d EdgeDirection(int a, int b) const {
    const Eigen::Vector3d d =
        a < b ? set_.Normal(a).cross(set_.Normal(b)) : set_.Normal(b).cross(set_.Normal(a));
    return d.normalized();
  }

  // Corners of the face's other trapezoids on the vertical side at `lambda` strictly between
  // `lo` and `hi`, upwards (or downwards if `down`), into `out`.
  static void SideCuts(const FaceCorners& face, double lambda, const Corner& lo, const Corner& hi,
                       bool down, std::vector<Corner>& out) {
    out.clear();
    const auto first =
        std::lower_bound(face.boundary.begin(), face.boundary.end(), lambda,
                         [](const BoundaryCorner& c, double value) { return c.lambda < value; });
    for (auto it = first; it != face.boundary.end() && it->lambda == lambda; ++it) {
      const Corner& c = it->corner;
      if (c.w > lo.w && c.w < hi.w && c.vertex != lo.vertex && c.vertex != hi.vertex &&
          (out.empty() || out.back().vertex != c.vertex)) {
        out.push_back(c);
      }
    }
    if (down) std::reverse(out.begin(), out.end());
  }

  // True if counter-clockwise chart polygons face out of the hull.
  bool ChartIsOutward(const FaceRegion& region, const ConePlane& plane) const {
    const Eigen::Vector3d x0 = region.Point(0, region.w_min);
    const Eigen::Vector3d x1 = region.Point(1, region.w_min);
    const Eigen::Vector3d x2 = region.Point(0, region.w_max);
    const Eigen::Vector3d chart_normal = (x1 - x0).cross(x2 - x0);
    const Eigen::Vector2d edge = plane.q - plane.p;
    const Eigen::Vector2d inside = 0.5 * (plane.p + plane.q) + Eigen::Vector2d(-edge.y(), edge.x());
    const Eigen::Vector3d ray = set_.Ray(plane.view, inside);
    Eigen::Vector3d outward = region.d_p.cross(region.d_q);
    if (outward.dot(ray) > 0) outward = -outward;
    return chart_normal.dot(outward) > 0;
  }

  const ConePlaneSet& set_;
  std::vector<FaceCorners> faces_;  // by plane
  std::unordered_map<VertexKey, int, VertexKeyHash> ids_;
  std::vector<std::pair<uint64_t, int>> cuts_;  // (EdgeKey(face, line), vertex), sorted
  std::vector<ChartVertex> polygon_, edge_;     // scratch of AddTriangles
  std::vector<Corner> side_;
  int registered_cuts_ = 0;  // the faces' cuts RegisterNames numbered
  mutable std::vector<std::pair<double, ChartVertex>> ordered_cuts_;  // scratch of EdgeCuts
  std::vector<Eigen::Vector3d> positions_;
  std::vector<std::array<int, 3>> planes_;  // per position: the cone planes it lies on, or -1
  std::vector<int> mesh_index_;             // per position: its vertex in the last Mesh()
  std::vector<std::array<int32_t, 3>> triangles_;
  PolyhedralHullStats stats_;
};

}  // namespace

FaceAssembly AssembleFaces(const ConePlaneSet& set, const std::vector<FaceRegion>& regions,
                           bool with_cuts, int threads, double weld_tolerance,
                           bool keep_vertex_planes) {
  FaceAssembly assembly;
  HullAssembler assembler(set);
  if (with_cuts) {
    for (const FaceRegion& region : regions)
      assembler.AddCorners(region);
    assembler.IndexCuts();
    for (const FaceRegion& region : regions)
      assembler.AddTriangles(region);
  } else if (!assembler.AddFacePolygons(regions, threads)) {
    return assembly;
  }
  assembly.success = true;
  assembly.mesh = assembler.Mesh(weld_tolerance);
  assembly.stats = assembler.Stats();
  assembly.check = CheckClosedManifold(assembly.mesh);
  if (assembly.Open() || keep_vertex_planes)
    assembly.vertex_planes = assembler.MeshVertexPlanes(assembly.mesh.vertices.size());
  return assembly;
}

}  // namespace silnet::aggregator
