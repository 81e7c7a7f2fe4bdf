#include "aggregator/report/display_mesh.h"

#include <Eigen/Geometry>
#include <cmath>
#include <unordered_map>

namespace silnet::aggregator {
namespace {

// The mesh with its vertices merged per cell of edge `cell` (each at its cluster's mean).
DisplayMesh Cluster(const TriangleMesh& mesh, const Eigen::Vector3f& origin, double cell) {
  DisplayMesh out;
  out.cell = cell;
  std::unordered_map<uint64_t, uint32_t> cluster_of_key;
  std::vector<uint32_t> cluster_of_vertex(mesh.vertices.size());
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d p = (mesh.vertices[v] - origin).cast<double>() / cell;
    const auto key = (static_cast<uint64_t>(std::floor(p.x())) & 0x1FFFFF) |
                     ((static_cast<uint64_t>(std::floor(p.y())) & 0x1FFFFF) << 21) |
                     ((static_cast<uint64_t>(std::floor(p.z())) & 0x1FFFFF) << 42);
    const auto [it, inserted] = cluster_of_key.emplace(key, static_cast<uint32_t>(sums.size()));
    if (inserted) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    cluster_of_vertex[v] = it->second;
    sums[it->second] += mesh.vertices[v].cast<double>();
    ++counts[it->second];
  }
  out.positions.reserve(sums.size());
  for (size_t c = 0; c < sums.size(); ++c)
    out.positions.push_back((sums[c] / counts[c]).cast<float>());
  // A triangle is kept unless it collapsed or clustering turned it over (a fold the browser
  // would shade from behind).
  const auto normal = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                         const Eigen::Vector3f& c) { return (b - a).cross(c - a); };
  for (const auto& t : mesh.triangles) {
    const std::array<uint32_t, 3> m = {cluster_of_vertex[static_cast<size_t>(t[0])],
                                       cluster_of_vertex[static_cast<size_t>(t[1])],
                                       cluster_of_vertex[static_cast<size_t>(t[2])]};
    if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) continue;
    const Eigen::Vector3f before =
        normal(mesh.vertices[static_cast<size_t>(t[0])], mesh.vertices[static_cast<size_t>(t[1])],
               mesh.vertices[static_cast<size_t>(t[2])]);
    const Eigen::Vector3f after =
        normal(out.positions[m[0]], out.positions[m[1]], out.positions[m[2]]);
    if (before.dot(after) > 0) out.triangles.push_back(m);
  }
  return out;
}

// Sets the normals: area-weighted means of the faces around each vertex.
void AddNormals(DisplayMesh* mesh) {
  std::vector<Eigen::Vector3d> sums(mesh->positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh->triangles) {
    const Eigen::Vector3d a = mesh->positions[t[0]].cast<double>();
    const Eigen::Vector3d n =
        (mesh->positions[t[1]].cast<double>() - a).cross(mesh->positions[t[2]].cast<double>() - a);
    for (uint32_t v : t)
      sums[v] += n;  // |n| is twice the area: area weighting
  }
  mesh->normals.resize(sums.size());
  for (size_t v = 0; v < sums.size(); ++v) {
    const double length = sums[v].norm();
    mesh->normals[v] =
        length > 0 ? Eigen::Vector3f((sums[v] / length).cast<float>()) : Eigen::Vector3f::Zero();
  }
}

}  // namespace

DisplayMesh MakeDisplayMesh(const TriangleMesh& mesh, size_t max_triangles) {
  DisplayMesh out;
  if (mesh.triangles.size() <= max_triangles || mesh.vertices.empty()) {
    out.positions = mesh.vertices;
    for (const auto& t : mesh.triangles)
      out.triangles.push_back(
          {static_cast<uint32_t>(t[0]), static_cast<uint32_t>(t[1]), static_cast<uint32_t>(t[2])});
  } else {
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& v : mesh.vertices)
      box.extend(v);
    const Eigen::Vector3f origin = box.min() - Eigen::Vector3f::Constant(1e-6f);
    double cell = std::max(1e-9, static_cast<double>(box.diagonal().norm()) / 2000);
    do {
      out = Cluster(mesh, origin, cell);
      cell *= 1.25;
    } while (out.triangles.size() > max_triangles);
  }
  AddNormals(&out);
  return out;
}

}  // namespace silnet::aggregator
