#include "aggregator/stereo/triangle_remeshing.h"

#include <algorithm>
#include <unordered_map>

namespace silnet::aggregator {
namespace {

uint64_t EdgeKey(int32_t a, int32_t b) {
  const auto lo = static_cast<uint32_t>(std::min(a, b)), hi = static_cast<uint32_t>(std::max(a, b));
  return (static_cast<uint64_t>(lo) << 32) | hi;
}

// The mesh's edges, each with its midpoint id once it is bisected (-1 before).
class EdgeMarks {
 public:
  explicit EdgeMarks(size_t triangles) { marks_.reserve(3 * triangles / 2 + 1); }
  bool Marked(int32_t a, int32_t b) const {
    const auto it = marks_.find(EdgeKey(a, b));
    return it != marks_.end();
  }
  // Marks the edge; false if it was marked already.
  bool Mark(int32_t a, int32_t b) { return marks_.emplace(EdgeKey(a, b), -1).second; }
  int32_t& Midpoint(int32_t a, int32_t b) { return marks_.at(EdgeKey(a, b)); }
  size_t size() const { return marks_.size(); }

 private:
  std::unordered_map<uint64_t, int32_t> marks_;
};

using Triangle = std::array<int32_t, 3>;

// How many of the triangle's edges (edge e from corner e to e + 1) are marked, and which.
int MarkedEdges(const EdgeMarks& marks, const Triangle& t, std::array<bool, 3>* which) {
  int count = 0;
  for (size_t e = 0; e < 3; ++e) {
    (*which)[e] = marks.Marked(t[e], t[(e + 1) % 3]);
    count += (*which)[e];
  }
  return count;
}

}  // namespace

bool SubdivideLongEdges(TriangleMesh* mesh, const EdgeSplitTest& split, size_t max_triangles,
                        SubdivisionStats* stats, std::vector<std::array<int32_t, 2>>* parents) {
  SubdivisionStats local;
  SubdivisionStats& s = stats ? *stats : local;
  s = SubdivisionStats{};
  EdgeMarks marks(mesh->triangles.size());
  for (const Triangle& t : mesh->triangles) {
    for (size_t e = 0; e < 3; ++e) {
      const int32_t a = t[e], b = t[(e + 1) % 3];
      if (a < b && split(a, b)) {
        marks.Mark(a, b);
        ++s.edges_split;
      }
    }
  }
  if (marks.size() == 0) return false;
  // Closure: a triangle with two bisected edges gets its third; repeat until none is left.
  for (bool changed = true; changed;) {
    changed = false;
    std::array<bool, 3> which{};
    for (const Triangle& t : mesh->triangles) {
      if (MarkedEdges(marks, t, &which) != 2) continue;
      for (size_t e = 0; e < 3; ++e) {
        if (!which[e] && marks.Mark(t[e], t[(e + 1) % 3])) {
          ++s.closure;
          changed = true;
        }
      }
    }
  }
  std::array<bool, 3> which{};
  size_t triangles = 0;
  for (const Triangle& t : mesh->triangles) {
    const int count = MarkedEdges(marks, t, &which);
    triangles += count == 0 ? 1 : count == 1 ? 2 : 4;
  }
  if (triangles > max_triangles) return false;
  if (parents) parents->clear();

  std::vector<Triangle> next;
  next.reserve(triangles);
  const auto midpoint = [&](int32_t a, int32_t b) {
    int32_t& id = marks.Midpoint(a, b);
    if (id < 0) {
      id = static_cast<int32_t>(mesh->vertices.size());
      mesh->vertices.push_back(
          0.5f * (mesh->vertices[static_cast<size_t>(a)] + mesh->vertices[static_cast<size_t>(b)]));
      if (parents) parents->push_back({a, b});
    }
    return id;
  };
  for (const Triangle& t : mesh->triangles) {
    const int count = MarkedEdges(marks, t, &which);
    if (count == 0) {
      next.push_back(t);
    } else if (count == 1) {
      const size_t e =
          static_cast<size_t>(std::find(which.begin(), which.end(), true) - which.begin());
      const int32_t a = t[e], b = t[(e + 1) % 3], c = t[(e + 2) % 3];
      const int32_t m = midpoint(a, b);
      next.push_back({a, m, c});
      next.push_back({m, b, c});
      ++s.green;
    } else {
      const int32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
      ++s.red;
    }
  }
  mesh->triangles.swap(next);
  return true;
}

}  // namespace silnet::aggregator
