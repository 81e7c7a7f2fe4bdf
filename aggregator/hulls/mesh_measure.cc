#include "aggregator/hulls/mesh_measure.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "aggregator/hulls/nearest_point.h"

namespace silnet::aggregator {
namespace {

Eigen::Vector3d Vertex(const TriangleMesh& mesh, int32_t index) {
  return mesh.vertices[static_cast<size_t>(index)].cast<double>();
}

// Nearest-neighbour distances from every point of `from` to the set `to`.
void DirectedDistances(const std::vector<Eigen::Vector3d>& from,
                       const std::vector<Eigen::Vector3d>& to, double& max, double& mean) {
  max = mean = 0;
  if (from.empty() || to.empty()) return;
  double sum = 0;
  for (double d : NearestPoint(to).Distances(from)) {
    max = std::max(max, d);
    sum += d;
  }
  mean = sum / static_cast<double>(from.size());
}

}  // namespace

double MeshVolume(const TriangleMesh& mesh) {
  double six = 0;
  for (const auto& t : mesh.triangles)
    six += Vertex(mesh, t[0]).dot(Vertex(mesh, t[1]).cross(Vertex(mesh, t[2])));
  return six / 6.0;
}

VoxelGrid RasterizeMesh(const TriangleMesh& mesh, const VoxelGrid& like) {
  VoxelGrid grid = VoxelGrid::Empty(like.origin, like.voxel_size, like.dims);
  const double s = grid.voxel_size;
  // Crossings of each (i, j) column's z line with the triangles, then parity fill.
  std::vector<std::vector<double>> columns(static_cast<size_t>(grid.dims[0]) *
                                           static_cast<size_t>(grid.dims[1]));
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = Vertex(mesh, t[0]), b = Vertex(mesh, t[1]), c = Vertex(mesh, t[2]);
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (area == 0) continue;  // parallel to z: no crossing
    const auto index_range = [&](double lo, double hi, int axis) {
      const int first =
          std::max(0, static_cast<int>(std::ceil((lo - grid.origin[axis]) / s - 0.5)));
      const int last = std::min(grid.dims[static_cast<size_t>(axis)] - 1,
                                static_cast<int>(std::floor((hi - grid.origin[axis]) / s - 0.5)));
      return std::pair<int, int>(first, last);
    };
    const auto [i0, i1] =
        index_range(std::min({a.x(), b.x(), c.x()}), std::max({a.x(), b.x(), c.x()}), 0);
    const auto [j0, j1] =
        index_range(std::min({a.y(), b.y(), c.y()}), std::max({a.y(), b.y(), c.y()}), 1);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const double x = grid.origin.x() + (i + 0.5) * s, y = grid.origin.y() + (j + 0.5) * s;
        // Barycentric coordinates in xy, half-open on edges so shared edges count once.
        const double u = ((b.x() - x) * (c.y() - y) - (b.y() - y) * (c.x() - x)) / area;
        const double v = ((c.x() - x) * (a.y() - y) - (c.y() - y) * (a.x() - x)) / area;
        const double w = 1 - u - v;
        if (u < 0 || v < 0 || w < 0 || (u == 0 && v == 0) || (v == 0 && w == 0) ||
            (w == 0 && u == 0))
          continue;
        columns[static_cast<size_t>(j) * static_cast<size_t>(grid.dims[0]) + static_cast<size_t>(i)]
            .push_back(u * a.z() + v * b.z() + w * c.z());
      }
    }
  }
  for (int j = 0; j < grid.dims[1]; ++j) {
    for (int i = 0; i < grid.dims[0]; ++i) {
      auto& zs = columns[static_cast<size_t>(j) * static_cast<size_t>(grid.dims[0]) +
                         static_cast<size_t>(i)];
      std::sort(zs.begin(), zs.end());
      for (size_t k = 0; k + 1 < zs.size(); k += 2) {
        for (int z = 0; z < grid.dims[2]; ++z) {
          const double centre = grid.origin.z() + (z + 0.5) * s;
          if (centre > zs[k] && centre < zs[k + 1]) grid.occupied[grid.Index(i, j, z)] = 1;
        }
      }
    }
  }
  return grid;
}

namespace {

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  const double denom = 1 / (va + vb + vc);
  return (p - (a + ab * vb * denom + ac * vc * denom)).norm();
}

}  // namespace

double PointMeshDistance(const TriangleMesh& mesh, const Eigen::Vector3d& point) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    best = std::min(best, PointTriangleDistance(point, Vertex(mesh, t[0]), Vertex(mesh, t[1]),
                                                Vertex(mesh, t[2])));
  }
  return best;
}

std::vector<Eigen::Vector3d> SampleMeshSurface(const TriangleMesh& mesh, size_t count,
                                               std::mt19937_64& rng) {
  std::vector<double> cumulative;
  double total = 0;
  for (const auto& t : mesh.triangles) {
    total += 0.5 * (Vertex(mesh, t[1]) - Vertex(mesh, t[0]))
                       .cross(Vertex(mesh, t[2]) - Vertex(mesh, t[0]))
                       .norm();
    cumulative.push_back(total);
  }
  std::vector<Eigen::Vector3d> samples;
  if (total <= 0) return samples;
  std::uniform_real_distribution<double> uniform(0, 1);
  for (size_t k = 0; k < count; ++k) {
    const size_t t = static_cast<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), uniform(rng) * total) -
        cumulative.begin());
    const auto& tri = mesh.triangles[std::min(t, mesh.triangles.size() - 1)];
    double u = uniform(rng), v = uniform(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const Eigen::Vector3d a = Vertex(mesh, tri[0]);
    samples.push_back(a + u * (Vertex(mesh, tri[1]) - a) + v * (Vertex(mesh, tri[2]) - a));
  }
  return samples;
}

SurfaceDistances MeasureSurfaceDistances(const std::vector<Eigen::Vector3d>& a,
                                         const std::vector<Eigen::Vector3d>& b) {
  SurfaceDistances d;
  DirectedDistances(a, b, d.a_to_b_max, d.a_to_b_mean);
  DirectedDistances(b, a, d.b_to_a_max, d.b_to_a_mean);
  return d;
}

}  // namespace silnet::aggregator
