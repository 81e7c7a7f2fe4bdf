#pragma once
// Face steps from a cut's interior through the hull: for every hull cell within a few steps of
// an interior cell, how many steps and which face neighbour lies one step closer. The
// silhouette step (silhouette_repair.h) uses it to choose, on a missed pixel's ray, the cell
// nearest the model and to tie the cells between them to the inside too, so the cells it forces
// join the model instead of floating beside it as separate pieces.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {

// The steps of every cell of a lattice to its nearest interior cell, up to a bound.
class StepsToInterior {
 public:
  static constexpr int kMaxSteps = 15;  // the largest bound Compute accepts

  // Breadth-first from the interior cells of `interior` through the occupied cells of `hull`
  // (both on one lattice: CheckError otherwise), six face neighbours per step, at most
  // `max_steps` (1..kMaxSteps, CheckError otherwise) steps.
  static StepsToInterior Compute(const VoxelGrid& hull, const VoxelGrid& interior, int max_steps);

  // Steps from cell `c` to the interior: 0 for an interior cell, 1..max_steps for a hull cell
  // that many face steps away through hull cells, -1 for any other cell.
  int Steps(size_t c) const;

  // The cells strictly between `c` and the interior along one shortest path (Steps(c) - 1 of
  // them, nearest `c` first; none when Steps(c) <= 1). Every one is a hull cell and not interior.
  std::vector<size_t> Bridge(size_t c) const;

 private:
  static constexpr uint8_t kFar = 0xff;
  // Per cell: kFar, or steps * 8 + the direction (0..5: -x, +x, -y, +y, -z, +z) of the
  // neighbour one step closer (0 for interior cells).
  std::vector<uint8_t> code_;
  std::array<int, 3> dims_ = {0, 0, 0};

  size_t Neighbour(size_t c, int direction) const;
};

}  // namespace silnet::aggregator
