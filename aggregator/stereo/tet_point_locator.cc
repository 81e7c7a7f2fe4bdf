#include "aggregator/stereo/tet_point_locator.h"

#include <algorithm>
#include <cmath>

#include "shared/util/check.h"

namespace silnet::aggregator {

TetPointLocator::TetPointLocator(const TetMesh& mesh, double bucket_size)
    : mesh_(mesh), bucket_(bucket_size) {
  SILNET_CHECK(bucket_size > 0);
  if (mesh.tetrahedra.empty()) return;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices)
    box.extend(v);
  origin_ = box.min();
  for (int a = 0; a < 3; ++a)
    dims_[a] = std::max(1, static_cast<int>(std::ceil(box.sizes()[a] / bucket_)));
  const auto cell = [&](const Eigen::Vector3d& p, int a) {
    return std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / bucket_)), 0, dims_[a] - 1);
  };
  const size_t buckets = static_cast<size_t>(dims_.x()) * dims_.y() * dims_.z();
  SILNET_CHECK_MSG(buckets < (size_t{1} << 32), "too many buckets");
  // Two passes: count, then fill.
  std::vector<uint32_t> count(buckets + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
      Eigen::AlignedBox3d tet_box;
      for (int32_t v : mesh.tetrahedra[t])
        tet_box.extend(mesh.vertices[v]);
      for (int z = cell(tet_box.min(), 2); z <= cell(tet_box.max(), 2); ++z) {
        for (int y = cell(tet_box.min(), 1); y <= cell(tet_box.max(), 1); ++y) {
          for (int x = cell(tet_box.min(), 0); x <= cell(tet_box.max(), 0); ++x) {
            const size_t b =
                x + static_cast<size_t>(dims_.x()) * (y + static_cast<size_t>(dims_.y()) * z);
            if (pass == 0)
              ++count[b + 1];
            else
              ids_[count[b]++] = static_cast<int32_t>(t);
          }
        }
      }
    }
    if (pass == 0) {
      for (size_t b = 0; b < buckets; ++b)
        count[b + 1] += count[b];
      first_ = count;
      ids_.resize(count[buckets]);
    }
  }
}

int32_t TetPointLocator::Locate(const Eigen::Vector3d& p) const {
  if (first_.empty()) return -1;
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - origin_[a]) / bucket_);
    if (f < 0 || f >= dims_[a]) return -1;
    c[a] = static_cast<int>(f);
  }
  const size_t b =
      c.x() + static_cast<size_t>(dims_.x()) * (c.y() + static_cast<size_t>(dims_.y()) * c.z());
  for (uint32_t k = first_[b]; k < first_[b + 1]; ++k) {
    const Tetrahedron& t = mesh_.tetrahedra[ids_[k]];
    const Eigen::Vector3d& a = mesh_.vertices[t[0]];
    const Eigen::Vector3d& b1 = mesh_.vertices[t[1]];
    const Eigen::Vector3d& c1 = mesh_.vertices[t[2]];
    const Eigen::Vector3d& d = mesh_.vertices[t[3]];
    const double whole = SignedVolume6(a, b1, c1, d);
    const double eps = -1e-12 * std::abs(whole);
    if (SignedVolume6(p, b1, c1, d) >= eps && SignedVolume6(a, p, c1, d) >= eps &&
        SignedVolume6(a, b1, p, d) >= eps && SignedVolume6(a, b1, c1, p) >= eps)
      return ids_[k];
  }
  return -1;
}

}  // namespace silnet::aggregator
