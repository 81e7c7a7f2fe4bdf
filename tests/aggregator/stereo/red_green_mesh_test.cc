#include "aggregator/stereo/red_green_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>

#include "aggregator/stereo/bcc_lattice.h"

namespace silnet::aggregator {
namespace {

// The six edge lengths of a tetrahedron, sorted.
std::array<double, 6> SortedEdges(const TetMesh& mesh, const Tetrahedron& t) {
  std::array<double, 6> lengths{};
  int k = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      lengths[k++] = (mesh.vertices[t[a]] - mesh.vertices[t[b]]).norm();
  std::sort(lengths.begin(), lengths.end());
  return lengths;
}

// The faces of a mesh with how many tetrahedra have them.
std::map<std::array<int32_t, 3>, int> FaceCounts(const TetMesh& mesh) {
  std::map<std::array<int32_t, 3>, int> faces;
  for (const Tetrahedron& t : mesh.tetrahedra) {
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int32_t, 3> f{};
      int k = 0;
      for (int c = 0; c < 4; ++c)
        if (c != skip) f[k++] = t[c];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  }
  return faces;
}

double Volume(const TetMesh& mesh) {
  double volume = 0;
  for (const Tetrahedron& t : mesh.tetrahedra)
    volume += SignedVolume6(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]],
                            mesh.vertices[t[3]]) /
              6;
  return volume;
}

// True if p lies in the triangle (a, b, c), within `tolerance`.
bool InTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                const Eigen::Vector3d& c, double tolerance) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.norm();
  if (std::abs((p - a).dot(n)) / area2 > tolerance) return false;
  const double u = (c - b).cross(p - b).dot(n) / (area2 * area2);
  const double v = (a - c).cross(p - c).dot(n) / (area2 * area2);
  const double w = 1 - u - v;
  return u > -1e-9 && v > -1e-9 && w > -1e-9;
}

// Checks that `refined` fills exactly what `base` fills, conformingly: positive volumes
// summing to the base's, every face shared by two tetrahedra or lying on one of the base's
// own boundary faces (a hanging vertex leaves a face only one side has).
void ExpectConformingRefinementOf(const TetMesh& base, const TetMesh& refined) {
  for (const Tetrahedron& t : refined.tetrahedra)
    ASSERT_GT(SignedVolume6(refined.vertices[t[0]], refined.vertices[t[1]], refined.vertices[t[2]],
                            refined.vertices[t[3]]),
              0);
  std::vector<std::array<int32_t, 3>> boundary;
  for (const auto& [f, count] : FaceCounts(base))
    if (count == 1) boundary.push_back(f);
  size_t open = 0;
  for (const auto& [f, count] : FaceCounts(refined)) {
    ASSERT_LE(count, 2);
    if (count == 2) continue;
    const Eigen::Vector3d centroid =
        (refined.vertices[f[0]] + refined.vertices[f[1]] + refined.vertices[f[2]]) / 3;
    const bool on_boundary = std::any_of(boundary.begin(), boundary.end(), [&](const auto& b) {
      return InTriangle(centroid, base.vertices[b[0]], base.vertices[b[1]], base.vertices[b[2]],
                        1e-9);
    });
    if (!on_boundary) ++open;
  }
  EXPECT_EQ(open, 0u) << "faces with one side only, inside the mesh";
  EXPECT_NEAR(Volume(refined), Volume(base), 1e-9 * Volume(base));
}

TEST(BccLattice, CongruentTetrahedraFillTheBox) {
  const WorldBox box(Eigen::Vector3d(-0.3, 0.1, 0.2), Eigen::Vector3d(0.5, 0.7, 0.6));
  const double h = 0.1;
  const TetMesh mesh = BuildBccLattice(box, h);
  // 8 x 6 x 4 cubes: four tetrahedra per face of the grid.
  const size_t faces = 9 * 6 * 4 + 8 * 7 * 4 + 8 * 6 * 5;
  EXPECT_EQ(mesh.tetrahedra.size(), 4 * faces);
  const std::array<double, 6> expected = {std::sqrt(3.0) / 2 * h,
                                          std::sqrt(3.0) / 2 * h,
                                          std::sqrt(3.0) / 2 * h,
                                          std::sqrt(3.0) / 2 * h,
                                          h,
                                          h};
  for (const Tetrahedron& t : mesh.tetrahedra) {
    const auto lengths = SortedEdges(mesh, t);
    for (int e = 0; e < 6; ++e)
      ASSERT_NEAR(lengths[e], expected[e], 1e-12);
  }
  // They fill the box and, beyond each face of the grid on its sides, the half of that
  // face's octahedron outside (a pyramid of volume h^3 / 6).
  const double side_faces = 2.0 * (6 * 4 + 8 * 4 + 8 * 6);
  EXPECT_NEAR(Volume(mesh), box.volume() + side_faces * h * h * h / 6, 1e-9);
  for (const auto& [face, count] : FaceCounts(mesh))
    ASSERT_LE(count, 2);
}

TEST(RedGreenMesh, RedChildrenAreCongruentAtHalfTheSize) {
  const WorldBox box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const TetMesh base = BuildBccLattice(box, 0.5);
  RedGreenMesh mesh(base);
  const size_t roots = mesh.LeafCount();
  EXPECT_EQ(mesh.Refine({7}), 1u);  // one tetrahedron: its neighbours take green forms
  EXPECT_EQ(mesh.LeafCount(), roots + 7);
  TetMesh view{mesh.Vertices(), {}};
  const auto parent = SortedEdges(view, mesh.Corners(7));
  for (int32_t leaf : mesh.Leaves()) {
    if (mesh.Level(leaf) != 1) continue;
    const auto child = SortedEdges(view, mesh.Corners(leaf));
    for (int e = 0; e < 6; ++e)
      EXPECT_NEAR(child[e], parent[e] / 2, 1e-12);
  }
  const ConformingTetMesh conforming = mesh.Conform();
  EXPECT_GT(std::count(conforming.green.begin(), conforming.green.end(), 1), 0);
}

// Refines the leaves a sphere's surface passes through, `rounds` times, and returns the mesh.
RedGreenMesh RefineAroundSphere(const WorldBox& box, double spacing, int rounds,
                                const Eigen::Vector3d& centre, double radius) {
  RedGreenMesh mesh(BuildBccLattice(box, spacing));
  for (int r = 0; r < rounds; ++r) {
    std::vector<int32_t> crossing;
    for (int32_t leaf : mesh.Leaves()) {
      bool inside = false, outside = false;
      for (int32_t v : mesh.Corners(leaf)) {
        const double d = (mesh.Vertices()[v] - centre).norm() - radius;
        (d < 0 ? inside : outside) = true;
      }
      if (inside && outside) crossing.push_back(leaf);
    }
    mesh.Refine(crossing);
  }
  return mesh;
}

TEST(RedGreenMesh, RefinementAroundASurfaceStaysConforming) {
  const WorldBox box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const RedGreenMesh mesh =
      RefineAroundSphere(box, 0.125, 3, Eigen::Vector3d(0.45, 0.5, 0.52), 0.31);
  const ConformingTetMesh conforming = mesh.Conform();
  ExpectConformingRefinementOf(BuildBccLattice(box, 0.125), conforming.mesh);
  // Every red cell is a BCC tetrahedron of its level's size.
  const double h = 0.125;
  TetMesh view{mesh.Vertices(), {}};
  for (int32_t leaf : mesh.Leaves()) {
    const double scale = std::ldexp(h, -mesh.Level(leaf));
    const auto lengths = SortedEdges(view, mesh.Corners(leaf));
    for (int e = 0; e < 6; ++e)
      ASSERT_NEAR(lengths[e], (e < 4 ? std::sqrt(3.0) / 2 : 1.0) * scale, 1e-12);
  }
  // Far fewer cells than the lattice at the finest level (8^3 times the roots).
  const size_t uniform = BuildBccLattice(box, 0.125).tetrahedra.size() * 512;
  EXPECT_LT(conforming.mesh.tetrahedra.size() * 5, uniform);
}

TEST(RedGreenMesh, RandomRefinementStaysConforming) {
  const WorldBox box(Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 0.75, 0.5));
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    std::mt19937 random(seed);
    RedGreenMesh mesh(BuildBccLattice(box, 0.25));
    for (int round = 0; round < 3; ++round) {
      std::vector<int32_t> chosen;
      for (int32_t leaf : mesh.Leaves())
        if (std::uniform_real_distribution<double>(0, 1)(random) < 0.08) chosen.push_back(leaf);
      mesh.Refine(chosen);
    }
    ExpectConformingRefinementOf(BuildBccLattice(box, 0.25), mesh.Conform().mesh);
  }
}

}  // namespace
}  // namespace silnet::aggregator
