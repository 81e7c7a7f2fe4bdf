#include "aggregator/stereo/steps_to_interior.h"

#include "shared/util/check.h"

namespace silnet::aggregator {

size_t StepsToInterior::Neighbour(size_t c, int direction) const {
  const size_t nx = static_cast<size_t>(dims_[0]);
  const size_t nxy = nx * static_cast<size_t>(dims_[1]);
  const size_t stride[3] = {1, nx, nxy};
  const size_t s = stride[direction / 2];
  return direction % 2 == 0 ? c - s : c + s;
}

StepsToInterior StepsToInterior::Compute(const VoxelGrid& hull, const VoxelGrid& interior,
                                         int max_steps) {
  SILNET_CHECK_MSG(hull.dims == interior.dims && hull.occupied.size() == hull.size() &&
                       interior.occupied.size() == interior.size(),
                   "the hull and the interior must share one lattice");
  SILNET_CHECK_MSG(max_steps >= 1 && max_steps <= kMaxSteps,
                   "steps to the interior: the bound must lie in 1.." << kMaxSteps);
  StepsToInterior steps;
  steps.dims_ = hull.dims;
  steps.code_.assign(hull.size(), kFar);
  const int nx = hull.dims[0], ny = hull.dims[1], nz = hull.dims[2];
  // Face neighbour of (i, j, k) in `direction`, if inside the grid.
  const auto in_grid = [&](int i, int j, int k, int direction) {
    const int axis = direction / 2, delta = direction % 2 == 0 ? -1 : 1;
    const int p[3] = {i + (axis == 0 ? delta : 0), j + (axis == 1 ? delta : 0),
                      k + (axis == 2 ? delta : 0)};
    return p[0] >= 0 && p[1] >= 0 && p[2] >= 0 && p[0] < nx && p[1] < ny && p[2] < nz;
  };
  std::vector<size_t> level;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const size_t c = hull.Index(i, j, k);
        if (interior.occupied[c] == 0) continue;
        steps.code_[c] = 0;
        for (int d = 0; d < 6; ++d) {
          if (!in_grid(i, j, k, d)) continue;
          const size_t n = steps.Neighbour(c, d);
          if (hull.occupied[n] != 0 && interior.occupied[n] == 0) {
            level.push_back(c);
            break;
          }
        }
      }
  std::vector<size_t> next;
  for (int step = 1; step <= max_steps && !level.empty(); ++step) {
    next.clear();
    for (size_t c : level) {
      const auto i = static_cast<int>(c % static_cast<size_t>(nx));
      const auto j = static_cast<int>(c / static_cast<size_t>(nx) % static_cast<size_t>(ny));
      const auto k = static_cast<int>(c / (static_cast<size_t>(nx) * static_cast<size_t>(ny)));
      for (int d = 0; d < 6; ++d) {
        if (!in_grid(i, j, k, d)) continue;
        const size_t n = steps.Neighbour(c, d);
        if (hull.occupied[n] == 0 || steps.code_[n] != kFar) continue;
        // The way back from n to c is the opposite direction.
        steps.code_[n] = static_cast<uint8_t>(step * 8 + (d ^ 1));
        next.push_back(n);
      }
    }
    level.swap(next);
  }
  return steps;
}

int StepsToInterior::Steps(size_t c) const {
  SILNET_CHECK(c < code_.size());
  return code_[c] == kFar ? -1 : code_[c] / 8;
}

std::vector<size_t> StepsToInterior::Bridge(size_t c) const {
  std::vector<size_t> bridge;
  for (int left = Steps(c); left > 1; --left) {
    c = Neighbour(c, code_[c] % 8);
    bridge.push_back(c);
  }
  return bridge;
}

}  // namespace silnet::aggregator
