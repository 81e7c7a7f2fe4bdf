#include "aggregator/stereo/vote_volume.h"

#include <cmath>

#include "shared/util/check.h"

namespace silnet::aggregator {

VoteVolume VoteVolume::Covering(const WorldBox& box, double cell_size) {
  SILNET_CHECK(!box.isEmpty() && cell_size > 0.0);
  const VoxelGrid grid = GridCovering(box, cell_size);
  VoteVolume volume;
  volume.origin = grid.origin;
  volume.cell_size = grid.voxel_size;
  volume.dims = grid.dims;
  volume.votes.assign(volume.size(), 0.0f);
  return volume;
}

std::optional<std::array<int, 3>> VoteVolume::CellOf(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d u = (p - origin) / cell_size;
  const std::array<int, 3> ijk = {static_cast<int>(std::floor(u.x())),
                                  static_cast<int>(std::floor(u.y())),
                                  static_cast<int>(std::floor(u.z()))};
  if (!InGrid(ijk[0], ijk[1], ijk[2])) return std::nullopt;
  return ijk;
}

double VoteVolume::Cost(size_t index, double lambda) const {
  return std::exp(-lambda * static_cast<double>(votes[index]));
}

}  // namespace silnet::aggregator
