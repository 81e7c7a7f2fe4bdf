#include "aggregator/stereo/crossing_faces.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>

#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {

std::array<int32_t, 3> SortedFace(int32_t a, int32_t b, int32_t c) {
  std::array<int32_t, 3> f{a, b, c};
  std::sort(f.begin(), f.end());
  return f;
}

CrossingFaces::CrossingFaces(const PatchScorer& scorer, const CrossingFaceOptions& options)
    : scorer_(scorer), options_(options) {
  SILNET_CHECK(options.sample_spacing > 0 && options.patch_step > 0);
  SILNET_CHECK(options.crossing_fraction > 0 && options.crossing_fraction <= 1);
}

namespace {

// This thread's list of a face's samples inside the silhouettes (lattice index, position).
std::vector<std::pair<size_t, Eigen::Vector3d>>& ThreadInside() {
  thread_local std::vector<std::pair<size_t, Eigen::Vector3d>> inside;
  return inside;
}

// A stride coprime to n near 0.618 n (1 for n < 3): k * stride mod n visits 0..n-1 once each,
// consecutive visits far apart.
size_t SpreadStride(size_t n) {
  if (n < 3) return 1;
  size_t stride = std::max<size_t>(1, static_cast<size_t>(0.618 * static_cast<double>(n)));
  while (std::gcd(stride, n) != 1)
    ++stride;
  return stride;
}

}  // namespace

const CrossingFaces::Part* CrossingFaces::Find(const std::array<int32_t, 3>& sorted_ids) const {
  const auto it = index_.find(sorted_ids);
  return it == index_.end() ? nullptr : &parts_[it->second];
}

void CrossingFaces::Add(const std::array<int32_t, 3>& sorted_ids, Part part) {
  SILNET_CHECK_MSG(parts_.size() < UINT32_MAX, "too many faces");
  if (!index_.try_emplace(sorted_ids, static_cast<uint32_t>(parts_.size())).second) return;
  parts_.push_back(std::move(part));
}

bool CrossingFaces::Known(const std::array<int32_t, 3>& ids) const {
  return Find(ids) != nullptr;
}

FaceSamples CrossingFaces::Counts(const std::array<int32_t, 3>& ids) const {
  const Part* part = Find(ids);
  SILNET_CHECK_MSG(part != nullptr, "face not sampled");
  return part->counts;
}

bool CrossingFaces::Crossing(const FaceSamples& counts) const {
  return counts.consistent > 0 && (counts.consistent >= options_.crossing_samples ||
                                   counts.consistent >= options_.crossing_fraction * counts.total);
}

FaceSamples CrossingFaces::CountPart(const Lattice& lattice,
                                     const std::array<std::array<int, 2>, 3>& c) {
  // Lattice points inside or on the triangle c (integer coordinates, exact).
  const int min_i = std::min({c[0][0], c[1][0], c[2][0]});
  const int max_i = std::max({c[0][0], c[1][0], c[2][0]});
  const int min_j = std::min({c[0][1], c[1][1], c[2][1]});
  const int max_j = std::max({c[0][1], c[1][1], c[2][1]});
  const auto edge = [](const std::array<int, 2>& a, const std::array<int, 2>& b, int i, int j) {
    return static_cast<int64_t>(b[0] - a[0]) * (j - a[1]) -
           static_cast<int64_t>(b[1] - a[1]) * (i - a[0]);
  };
  const int64_t orientation = edge(c[0], c[1], c[2][0], c[2][1]) > 0 ? 1 : -1;
  FaceSamples counts;
  const int n = lattice.n;
  for (int j = min_j; j <= max_j; ++j) {
    for (int i = min_i; i <= max_i; ++i) {
      if (orientation * edge(c[0], c[1], i, j) < 0 || orientation * edge(c[1], c[2], i, j) < 0 ||
          orientation * edge(c[2], c[0], i, j) < 0)
        continue;
      // Row j of the lattice starts after the rows below it: sum over r < j of (n + 1 - r).
      const int index = j * (n + 1) - j * (j - 1) / 2 + i;
      const uint8_t flags = lattice.flags[static_cast<size_t>(index)];
      ++counts.total;
      counts.inside += (flags & Lattice::kInside) ? 1 : 0;
      counts.consistent += (flags & Lattice::kConsistent) ? 1 : 0;
    }
  }
  return counts;
}

std::vector<size_t> CrossingFaces::FacesToSample(
    const std::vector<std::array<int32_t, 3>>& ids) const {
  std::vector<std::pair<std::array<int32_t, 3>, size_t>> unknown;
  for (size_t f = 0; f < ids.size(); ++f) {
    const auto sorted = SortedFace(ids[f][0], ids[f][1], ids[f][2]);
    if (!Find(sorted)) unknown.emplace_back(sorted, f);
  }
  std::sort(unknown.begin(), unknown.end());
  std::vector<size_t> fresh;
  for (size_t k = 0; k < unknown.size(); ++k)
    if (k == 0 || unknown[k].first != unknown[k - 1].first) fresh.push_back(unknown[k].second);
  return fresh;
}

void CrossingFaces::Sample(const std::vector<std::array<int32_t, 3>>& ids,
                           const std::vector<TriangleCorners>& corners,
                           std::vector<OrientedPoint>* points, Progress* progress,
                           bool keep_lattices) {
  Sample(ids, corners, FacesToSample(ids), points, progress, keep_lattices);
}

void CrossingFaces::Sample(const std::vector<std::array<int32_t, 3>>& ids,
                           const std::vector<TriangleCorners>& corners,
                           const std::vector<size_t>& fresh, std::vector<OrientedPoint>* points,
                           Progress* progress, bool keep_lattices) {
  SILNET_CHECK(ids.size() == corners.size());

  std::vector<Part> results(fresh.size());
  std::vector<OrientedPoint> best(fresh.size());
  std::vector<size_t> scored(fresh.size(), 0);
  ParallelFor(fresh.size(), options_.threads, progress, [&](size_t k) {
    const size_t f = fresh[k];
    const TriangleCorners& c = corners[f];
    const double longest =
        std::max({(c[1] - c[0]).norm(), (c[2] - c[1]).norm(), (c[0] - c[2]).norm()});
    int n = 1;
    while (longest / n > options_.sample_spacing && n < (1 << 12))
      n *= 2;
    auto lattice = std::make_shared<Lattice>();
    lattice->n = n;
    lattice->flags.assign(static_cast<size_t>((n + 1) * (n + 2) / 2), 0);
    // The samples inside the silhouettes, scored in a spread order so that a face cut short
    // has its scored samples all over it.
    std::vector<std::pair<size_t, Eigen::Vector3d>>& inside = ThreadInside();
    inside.clear();
    size_t index = 0;
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i + j <= n; ++i, ++index) {
        const Eigen::Vector3d x =
            c[0] + (double(i) / n) * (c[1] - c[0]) + (double(j) / n) * (c[2] - c[0]);
        if (!scorer_.InsideSilhouettes(x)) continue;
        lattice->flags[index] = Lattice::kInside;
        inside.emplace_back(index, x);
      }
    }
    const size_t total = lattice->flags.size();
    const size_t stride = SpreadStride(inside.size());
    OrientedPoint& top = best[k];
    top.score = -2.0f;
    int consistent = 0;
    for (size_t m = 0; m < inside.size(); ++m) {
      if (!keep_lattices && Crossing(FaceSamples{static_cast<int>(total), consistent, 0})) break;
      const auto& [at, x] = inside[(m * stride) % inside.size()];
      int orientation = 0;
      const PatchScore score =
          scorer_.BestPlane(x, options_.patch_step, options_.min_score - options_.prefilter_margin,
                            &orientation, options_.full_orientations);
      ++scored[k];
      if (score.score < options_.min_score) continue;
      lattice->flags[at] |= Lattice::kConsistent;
      ++consistent;
      if (score.score > top.score) {
        top.point = x;
        top.normal = CanonicalOrientations()[static_cast<size_t>(orientation)];
        top.score = score.score;
        top.view_mask = score.view_mask;
      }
    }
    Part& part = results[k];
    part.corner = {{{0, 0}, {n, 0}, {0, n}}};
    part.ids = ids[f];
    part.counts = CountPart(*lattice, part.corner);
    if (keep_lattices) part.lattice = std::move(lattice);
    if (progress) progress->Advance();
  });
  if (progress && progress->cancelled()) return;
  for (size_t k = 0; k < fresh.size(); ++k) {
    samples_scored_ += scored[k];
    if (best[k].score >= options_.min_score) points->push_back(best[k]);
    const auto sorted = SortedFace(results[k].ids[0], results[k].ids[1], results[k].ids[2]);
    Add(sorted, std::move(results[k]));
  }
  sampled_faces_ += fresh.size();
}

void CrossingFaces::Inherit(int32_t a, int32_t b, int32_t c, int32_t ab, int32_t bc, int32_t ca) {
  const Part* parent = Find(SortedFace(a, b, c));
  SILNET_CHECK_MSG(parent != nullptr, "face not sampled");
  if (!parent->lattice) return;  // sampled without keeping its lattice
  // The parent's lattice coordinates of a, b, c.
  std::array<int, 2> pa{}, pb{}, pc{};
  for (int k = 0; k < 3; ++k) {
    if (parent->ids[k] == a) pa = parent->corner[k];
    if (parent->ids[k] == b) pb = parent->corner[k];
    if (parent->ids[k] == c) pc = parent->corner[k];
  }
  const auto mid = [](const std::array<int, 2>& p, const std::array<int, 2>& q) {
    return std::array<int, 2>{(p[0] + q[0]) / 2, (p[1] + q[1]) / 2};
  };
  // The parts need a lattice point at every corner: the parent's edges of even length.
  const auto even = [](const std::array<int, 2>& p, const std::array<int, 2>& q) {
    return (p[0] + q[0]) % 2 == 0 && (p[1] + q[1]) % 2 == 0;
  };
  if (!even(pa, pb) || !even(pb, pc) || !even(pc, pa)) return;
  if (pa == pb) return;
  const std::array<int, 2> pab = mid(pa, pb), pbc = mid(pb, pc), pca = mid(pc, pa);
  const std::array<std::pair<std::array<int32_t, 3>, std::array<std::array<int, 2>, 3>>, 4> parts =
      {{
          {{a, ab, ca}, {pa, pab, pca}},
          {{ab, b, bc}, {pab, pb, pbc}},
          {{ca, bc, c}, {pca, pbc, pc}},
          {{ab, bc, ca}, {pab, pbc, pca}},
      }};
  const std::shared_ptr<const Lattice> lattice = parent->lattice;
  for (const auto& [ids, corner] : parts) {
    const auto sorted = SortedFace(ids[0], ids[1], ids[2]);
    if (Find(sorted)) continue;
    Part part;
    part.lattice = lattice;
    part.corner = corner;
    part.ids = ids;
    part.counts = CountPart(*lattice, corner);
    Add(sorted, std::move(part));
  }
}

}  // namespace silnet::aggregator
