#include "aggregator/stereo/red_green_mesh.h"

#include <algorithm>
#include <limits>
#include <utility>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

uint64_t EdgeKey(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

// The six edges of a tetrahedron as pairs of corner positions.
constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

}  // namespace

RedGreenMesh::RedGreenMesh(TetMesh base) : vertices_(std::move(base.vertices)) {
  tets_.reserve(base.tetrahedra.size());
  incident_leaves_.resize(vertices_.size());
  parent_edge_.assign(vertices_.size(), {-1, -1});
  for (const Tetrahedron& tet : base.tetrahedra) {
    for (int32_t v : tet)
      SILNET_CHECK(v >= 0 && static_cast<size_t>(v) < vertices_.size());
    tets_.push_back({tet, -1, 0});
    AddIncidence(static_cast<int32_t>(tets_.size() - 1));
  }
  leaf_count_ = tets_.size();
}

std::vector<int32_t> RedGreenMesh::Leaves() const {
  std::vector<int32_t> leaves;
  leaves.reserve(leaf_count_);
  for (size_t t = 0; t < tets_.size(); ++t)
    if (tets_[t].first_child < 0) leaves.push_back(static_cast<int32_t>(t));
  return leaves;
}

int32_t RedGreenMesh::Midpoint(int32_t a, int32_t b) const {
  const auto it = midpoints_.find(EdgeKey(a, b));
  return it == midpoints_.end() ? -1 : it->second;
}

int32_t RedGreenMesh::MakeMidpoint(int32_t a, int32_t b) {
  const auto [it, added] = midpoints_.try_emplace(EdgeKey(a, b), 0);
  if (added) {
    SILNET_CHECK_MSG(vertices_.size() < static_cast<size_t>(INT32_MAX), "mesh too large");
    it->second = static_cast<int32_t>(vertices_.size());
    vertices_.push_back(0.5 * (vertices_[a] + vertices_[b]));
    incident_leaves_.emplace_back();
    parent_edge_.push_back({a, b});
  }
  return it->second;
}

void RedGreenMesh::AddIncidence(int32_t tet) {
  for (int32_t v : tets_[tet].v)
    incident_leaves_[v].push_back(tet);
}

void RedGreenMesh::RemoveIncidence(int32_t tet) {
  for (int32_t v : tets_[tet].v) {
    std::vector<int32_t>& list = incident_leaves_[v];
    const auto it = std::find(list.begin(), list.end(), tet);
    if (it != list.end()) {
      *it = list.back();
      list.pop_back();
    }
  }
}

void RedGreenMesh::RedRefine(int32_t tet) {
  const Tetrahedron v = tets_[tet].v;
  int32_t m[6];
  for (int e = 0; e < 6; ++e)
    m[e] = MakeMidpoint(v[kEdges[e][0]], v[kEdges[e][1]]);
  // m[0]=01 m[1]=02 m[2]=03 m[3]=12 m[4]=13 m[5]=23
  std::array<Tetrahedron, 8> children = {{
      {v[0], m[0], m[1], m[2]},
      {m[0], v[1], m[3], m[4]},
      {m[1], m[3], v[2], m[5]},
      {m[2], m[4], m[5], v[3]},
  }};
  // The inner octahedron: three diagonals between opposite midpoints (01-23, 02-13, 03-12),
  // each with the ring of the other four in order around it.
  const int diagonals[3][2] = {{0, 5}, {1, 4}, {2, 3}};
  const int rings[3][4] = {{1, 2, 4, 3}, {0, 2, 5, 3}, {0, 1, 5, 4}};
  int best = 0;
  double best_length = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) {
    const double length =
        (vertices_[m[diagonals[d][0]]] - vertices_[m[diagonals[d][1]]]).squaredNorm();
    if (length < best_length - 1e-12 * best_length) {
      best_length = length;
      best = d;
    }
  }
  for (int r = 0; r < 4; ++r)
    children[4 + r] = {m[diagonals[best][0]], m[diagonals[best][1]], m[rings[best][r]],
                       m[rings[best][(r + 1) % 4]]};

  RemoveIncidence(tet);
  const auto first = static_cast<int32_t>(tets_.size());
  tets_[tet].first_child = first;
  const int32_t level = tets_[tet].level + 1;
  for (const Tetrahedron& child : children) {
    tets_.push_back({PositivelyOriented(child, vertices_), -1, level});
    AddIncidence(static_cast<int32_t>(tets_.size() - 1));
  }
  leaf_count_ += 7;
}

bool RedGreenMesh::GreenForm(int32_t tet, std::vector<Tetrahedron>* out) const {
  const Tetrahedron& v = tets_[tet].v;
  int32_t m[6];
  int split = 0, count = 0;
  for (int e = 0; e < 6; ++e) {
    m[e] = Midpoint(v[kEdges[e][0]], v[kEdges[e][1]]);
    if (m[e] >= 0) {
      split |= 1 << e;
      ++count;
    }
  }
  const size_t first = out->size();
  if (count == 0) {
    out->push_back(v);
    return true;
  }
  if (count == 1) {
    const int e = __builtin_ctz(static_cast<unsigned>(split));
    const int a = kEdges[e][0], b = kEdges[e][1];
    int others[2], k = 0;
    for (int c = 0; c < 4; ++c)
      if (c != a && c != b) others[k++] = c;
    out->push_back({v[a], m[e], v[others[0]], v[others[1]]});
    out->push_back({m[e], v[b], v[others[0]], v[others[1]]});
  } else if (count == 2) {
    const int e1 = __builtin_ctz(static_cast<unsigned>(split));
    const int e2 = __builtin_ctz(static_cast<unsigned>(split & ~(1 << e1)));
    const int a1 = kEdges[e1][0], b1 = kEdges[e1][1], a2 = kEdges[e2][0], b2 = kEdges[e2][1];
    int shared = -1;
    if (a1 == a2 || a1 == b2) shared = a1;
    if (b1 == a2 || b1 == b2) shared = b1;
    if (shared < 0) {  // opposite edges: four tetrahedra around the line between midpoints
      for (int x : {a1, b1})
        for (int y : {a2, b2})
          out->push_back({m[e1], m[e2], v[x], v[y]});
    } else {
      const int p = a1 == shared ? b1 : a1, q = a2 == shared ? b2 : a2;
      const int d = 6 - shared - p - q;
      const int32_t mp = m[e1], mq = m[e2];
      out->push_back({v[shared], mp, mq, v[d]});
      // The quad (mp, p, q, mq) cut by the diagonal from its smaller midpoint id, a rule of
      // the face alone, so the neighbour across it cuts it the same way.
      if (mp < mq) {
        out->push_back({mp, v[p], v[q], v[d]});
        out->push_back({mp, v[q], mq, v[d]});
      } else {
        out->push_back({mp, v[p], mq, v[d]});
        out->push_back({mq, v[p], v[q], v[d]});
      }
    }
  } else if (count == 3) {
    // Only the three edges of one face: the face 1:4, each part joined to the fourth corner.
    int face_missing = -1;
    for (int d = 0; d < 4 && face_missing < 0; ++d) {
      bool touches = false;
      for (int e = 0; e < 6; ++e)
        if ((split >> e) & 1) touches = touches || kEdges[e][0] == d || kEdges[e][1] == d;
      if (!touches) face_missing = d;
    }
    if (face_missing < 0) return false;
    int c[3], k = 0;
    for (int x = 0; x < 4; ++x)
      if (x != face_missing) c[k++] = x;
    const auto mid = [&](int x, int y) { return Midpoint(v[x], v[y]); };
    const int32_t d = v[face_missing];
    const int32_t m01 = mid(c[0], c[1]), m02 = mid(c[0], c[2]), m12 = mid(c[1], c[2]);
    out->push_back({v[c[0]], m01, m02, d});
    out->push_back({m01, v[c[1]], m12, d});
    out->push_back({m02, m12, v[c[2]], d});
    out->push_back({m01, m12, m02, d});
  } else {
    return false;
  }
  // A green cell must not have a split edge itself.
  for (size_t t = first; t < out->size(); ++t) {
    const Tetrahedron& g = (*out)[t];
    for (const auto& e : kEdges) {
      if (Midpoint(g[e[0]], g[e[1]]) >= 0) {
        out->resize(first);
        return false;
      }
    }
  }
  return true;
}

size_t RedGreenMesh::Refine(const std::vector<int32_t>& leaves) {
  std::vector<int32_t> pending(leaves);
  std::vector<int32_t> candidates;
  std::vector<Tetrahedron> scratch;
  // Per tetrahedron, the last round it became a candidate in (each is listed once a round).
  std::vector<uint32_t> listed;
  uint32_t round = 0;
  const auto list = [&](int32_t c) {
    if (listed.size() <= static_cast<size_t>(c)) listed.resize(tets_.size(), 0);
    if (listed[c] == round) return;
    listed[c] = round;
    candidates.push_back(c);
  };
  size_t refined = 0;
  while (!pending.empty()) {
    ++round;
    candidates.clear();
    for (int32_t t : pending) {
      SILNET_CHECK(t >= 0 && static_cast<size_t>(t) < tets_.size());
      if (!IsLeaf(t)) continue;
      // Every leaf with an edge the refinement splits has one of its corners; a leaf whose
      // green form has an edge between two of its edges' midpoints has a corner at an end of
      // the edge one of them halves.
      for (int32_t v : tets_[t].v) {
        for (int32_t u : {v, parent_edge_[v][0], parent_edge_[v][1]})
          if (u >= 0)
            for (int32_t c : incident_leaves_[u])
              list(c);
      }
      RedRefine(t);
      ++refined;
      for (int32_t c = tets_[t].first_child; c < tets_[t].first_child + 8; ++c)
        list(c);
    }
    // In id order, as the closure's result must not depend on the order found.
    std::sort(candidates.begin(), candidates.end());
    pending.clear();
    for (int32_t c : candidates) {
      scratch.clear();
      if (IsLeaf(c) && !GreenForm(c, &scratch)) pending.push_back(c);
    }
  }
  return refined;
}

ConformingTetMesh RedGreenMesh::Conform() const {
  ConformingTetMesh result;
  result.mesh.vertices = vertices_;
  std::vector<Tetrahedron> cells;
  for (size_t t = 0; t < tets_.size(); ++t) {
    if (tets_[t].first_child >= 0) continue;
    cells.clear();
    SILNET_CHECK_MSG(GreenForm(static_cast<int32_t>(t), &cells), "red-green closure incomplete");
    for (const Tetrahedron& cell : cells) {
      result.mesh.tetrahedra.push_back(PositivelyOriented(cell, vertices_));
      result.leaf.push_back(static_cast<int32_t>(t));
      result.green.push_back(cells.size() > 1 ? 1 : 0);
    }
  }
  return result;
}

}  // namespace silnet::aggregator
