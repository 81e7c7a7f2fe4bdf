#include "aggregator/stereo/taubin_smoothing.h"

#include <algorithm>
#include <cstdint>
#include <utility>

#include "shared/util/check.h"

namespace silnet::aggregator {

VertexNeighbours FindVertexNeighbours(const TriangleMesh& mesh) {
  std::vector<std::pair<int32_t, int32_t>> pairs;
  pairs.reserve(mesh.triangles.size() * 6);
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      const int32_t a = t[static_cast<size_t>(e)], b = t[static_cast<size_t>((e + 1) % 3)];
      pairs.emplace_back(a, b);
      pairs.emplace_back(b, a);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  VertexNeighbours n;
  n.begin.assign(mesh.vertices.size() + 1, 0);
  for (const auto& p : pairs)
    ++n.begin[static_cast<size_t>(p.first) + 1];
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    n.begin[v + 1] += n.begin[v];
  n.ids.reserve(pairs.size());
  for (const auto& p : pairs)
    n.ids.push_back(p.second);
  return n;
}

namespace {

// One Laplacian step of weight `w` (umbrella operator), each vertex then clamped to its box.
void LaplacianStep(const VertexNeighbours& n, double w, const std::vector<Eigen::Vector3f>& lo,
                   const std::vector<Eigen::Vector3f>& hi, std::vector<Eigen::Vector3f>& v) {
  std::vector<Eigen::Vector3f> next(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const size_t count = n.begin[i + 1] - n.begin[i];
    if (count == 0) {
      next[i] = v[i];
      continue;
    }
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (size_t k = n.begin[i]; k < n.begin[i + 1]; ++k)
      mean += v[static_cast<size_t>(n.ids[k])];
    mean /= static_cast<float>(count);
    next[i] = (v[i] + static_cast<float>(w) * (mean - v[i])).cwiseMax(lo[i]).cwiseMin(hi[i]);
  }
  v.swap(next);
}

}  // namespace

void TaubinSmooth(TriangleMesh* mesh, int iterations, double lambda, double mu,
                  const std::vector<Eigen::Vector3f>& lo, const std::vector<Eigen::Vector3f>& hi) {
  if (iterations <= 0 || mesh->vertices.empty()) return;
  TaubinSmooth(mesh, FindVertexNeighbours(*mesh), iterations, lambda, mu, lo, hi);
}

void TaubinSmooth(TriangleMesh* mesh, const VertexNeighbours& neighbours, int iterations,
                  double lambda, double mu, const std::vector<Eigen::Vector3f>& lo,
                  const std::vector<Eigen::Vector3f>& hi) {
  SILNET_CHECK(lo.size() == mesh->vertices.size() && hi.size() == mesh->vertices.size());
  SILNET_CHECK(neighbours.begin.size() == mesh->vertices.size() + 1);
  for (int it = 0; it < iterations; ++it) {
    LaplacianStep(neighbours, lambda, lo, hi, mesh->vertices);
    LaplacianStep(neighbours, mu, lo, hi, mesh->vertices);
  }
}

}  // namespace silnet::aggregator
