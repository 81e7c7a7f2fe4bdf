#pragma once
// Which faces of the adaptive tetrahedral mesh the unknown surface crosses (thesis 7.3.2).
// A face is sampled on a triangular lattice (spacing at most `sample_spacing`), every sample
// scored by its best plane patch over the canonical orientations (PatchScorer::BestPlane); a face
// is crossing when at least `crossing_fraction` of its samples, or at least `crossing_samples` of
// them, are photo-consistent. Samples outside a silhouette are outside the visual hull and never
// photo-consistent; they are not scored.
//
// A face is sampled once: its results are kept per sample, and when its tetrahedron is
// red-refined its four halves-by-midpoint faces inherit their parts of the lattice (the
// thesis's quad-tree per face: a face of 2^k divisions per edge splits into four of 2^(k-1)),
// so only faces new at a level (inside the refined cells) are sampled afresh.

#include <absl/container/flat_hash_map.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "aggregator/stereo/patch_photo_consistency.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the crossing test.
struct CrossingFaceOptions {
  double sample_spacing = 0.0;     // metres, > 0: of the faces' sample lattices
  double patch_step = 0.0;         // metres, > 0: between patch points (the pixel footprint)
  double min_score = 0.7;          // a sample is photo-consistent at or above this
  double prefilter_margin = 0.15;  // orientations scoring below min_score less this on every
                                   // other patch point are not scored in full ...
  int full_orientations = 2;       // ... nor are those beyond the best this many of the others
  double crossing_fraction = 0.2;  // of a face's samples
  int crossing_samples = 20;       // or at least this many
  int threads = 0;                 // 0 = every core
};

// A photo-consistent oriented point found while sampling (the quasi-dense cloud).
struct OrientedPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // the patch orientation, towards its views
  float score = 0.0f;
  uint64_t view_mask = 0;  // the views that scored it (bits of views < 64)
};

// A face's sample counts.
struct FaceSamples {
  int total = 0;
  int consistent = 0;
  int inside = 0;  // inside every silhouette (the visual hull)
  // True if the visual hull's surface passes through the face: some samples inside, some not.
  bool OnHullSurface() const { return inside > 0 && inside < total; }
};

// A triangle given by its corners' positions.
using TriangleCorners = std::array<Eigen::Vector3d, 3>;

// Sampled faces, keyed by their corner vertex ids.
class CrossingFaces {
 public:
  CrossingFaces(const PatchScorer& scorer, const CrossingFaceOptions& options);

  // The index in `ids` of each distinct face not known yet (the faces Sample would sample),
  // in the order of its sorted ids.
  std::vector<size_t> FacesToSample(const std::vector<std::array<int32_t, 3>>& ids) const;

  // Samples every face not known yet (in parallel) and appends each sampled face's best
  // photo-consistent sample to `points`. `ids` are the faces' sorted vertex ids, `corners`
  // their positions in the same order. `progress` (may be null) is advanced by one per face
  // sampled; once it is cancelled Sample stops and keeps nothing of this call: the faces stay
  // unknown. A face's lattice has 2^k divisions per edge, the fewest that keep the samples
  // within sample_spacing. Without `keep_lattices` (the last level tested: no face will be
  // split and tested again) a face's samples are scored only until they make it crossing,
  // its best point is the best of those, and its lattice is not kept (Inherit hands nothing
  // down from it).
  void Sample(const std::vector<std::array<int32_t, 3>>& ids,
              const std::vector<TriangleCorners>& corners, std::vector<OrientedPoint>* points,
              Progress* progress = nullptr, bool keep_lattices = true);
  // As above, with `fresh` = FacesToSample(ids) computed by the caller (no face known since).
  void Sample(const std::vector<std::array<int32_t, 3>>& ids,
              const std::vector<TriangleCorners>& corners, const std::vector<size_t>& fresh,
              std::vector<OrientedPoint>* points, Progress* progress, bool keep_lattices);

  // The face's counts; it must be known (sampled or inherited). CheckError otherwise.
  FaceSamples Counts(const std::array<int32_t, 3>& ids) const;
  // True if the face is known.
  bool Known(const std::array<int32_t, 3>& ids) const;
  // True if the counts make the face crossing.
  bool Crossing(const FaceSamples& counts) const;

  // Hands the known face (a, b, c) down to its four parts, given the midpoint ids of its
  // edges ab, bc and ca, when its lattice still has samples inside each part's corners. The
  // ids are vertex ids in any order; the parts are keyed sorted like every face.
  void Inherit(int32_t a, int32_t b, int32_t c, int32_t ab, int32_t bc, int32_t ca);

  size_t SampledFaces() const { return sampled_faces_; }
  size_t SamplesScored() const { return samples_scored_; }

 private:
  // One sampled face's lattice: (n + 1)(n + 2) / 2 flags (kInside, kConsistent), point
  // (i, j) at corner0 + i/n (corner1 - corner0) + j/n (corner2 - corner0).
  struct Lattice {
    static constexpr uint8_t kInside = 1, kConsistent = 2;
    int n = 0;
    std::vector<uint8_t> flags;
  };
  // A known face: its part of a lattice, given by its corners' lattice coordinates (i, j),
  // corner k belonging to the vertex id in the same place of `ids`.
  struct Part {
    std::shared_ptr<const Lattice> lattice;  // null if not kept
    std::array<std::array<int, 2>, 3> corner{};
    std::array<int32_t, 3> ids{};
    FaceSamples counts;
  };
  static FaceSamples CountPart(const Lattice& lattice, const std::array<std::array<int, 2>, 3>& c);

  const PatchScorer& scorer_;
  CrossingFaceOptions options_;
  std::vector<Part> parts_;
  absl::flat_hash_map<std::array<int32_t, 3>, uint32_t> index_;  // sorted ids -> part
  size_t sampled_faces_ = 0;
  size_t samples_scored_ = 0;

  const Part* Find(const std::array<int32_t, 3>& sorted_ids) const;
  // Keeps `part` under its sorted ids unless a part is kept there already.
  void Add(const std::array<int32_t, 3>& sorted_ids, Part part);
};

// The sorted vertex ids of a face.
std::array<int32_t, 3> SortedFace(int32_t a, int32_t b, int32_t c);

}  // namespace silnet::aggregator
