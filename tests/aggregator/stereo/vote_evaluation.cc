#include "tests/aggregator/stereo/vote_evaluation.h"

#include <cmath>

namespace silnet::aggregator::testing {

std::vector<double> VoteShareWithin(const VoteVolume& volume, const NearestPoint& truth,
                                    const std::vector<double>& distances) {
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> votes;
  for (int k = 0; k < volume.dims[2]; ++k)
    for (int j = 0; j < volume.dims[1]; ++j)
      for (int i = 0; i < volume.dims[0]; ++i) {
        const float v = volume.votes[volume.Index(i, j, k)];
        if (v <= 0.0f) continue;
        centres.push_back(volume.Center(i, j, k));
        votes.push_back(v);
      }
  const std::vector<double> nearest = truth.Distances(centres);
  double total = 0.0;
  std::vector<double> within(distances.size(), 0.0);
  for (size_t c = 0; c < centres.size(); ++c) {
    total += votes[c];
    for (size_t d = 0; d < distances.size(); ++d)
      if (nearest[c] <= distances[d]) within[d] += votes[c];
  }
  for (double& w : within)
    w = total > 0.0 ? w / total : 0.0;
  return within;
}

std::vector<RayMaximum> RayMaxima(const VoteVolume& volume, const std::vector<uint8_t>& solid,
                                  const StereoView& view, int step, float min_votes) {
  std::vector<RayMaximum> out;
  const CameraModel& camera = view.camera;
  const Eigen::Vector3d centre = camera.Center();
  const Eigen::Matrix3d back = camera.R.transpose() * camera.K.inverse();
  const double far = (centre - volume.origin).norm() +
                     volume.cell_size * (volume.dims[0] + volume.dims[1] + volume.dims[2]);
  for (int y = 0; y < view.mask.rows; y += step) {
    for (int x = 0; x < view.mask.cols; x += step) {
      if (view.mask.at<uint8_t>(y, x) == 0) continue;
      const Eigen::Vector3d direction = (back * Eigen::Vector3d(x, y, 1.0)).normalized();
      RayMaximum best;
      float best_votes = -1.0f;
      bool found = false;
      for (double s = 0.0; s < far; s += 0.5 * volume.cell_size) {
        const Eigen::Vector3d p = centre + s * direction;
        const auto ijk = volume.CellOf(p);
        if (!ijk) continue;
        const size_t index = volume.Index((*ijk)[0], (*ijk)[1], (*ijk)[2]);
        if (!best.has_solid_entry && solid[index] != 0) {
          best.has_solid_entry = true;
          best.solid_entry = p;
        }
        if (volume.votes[index] >= min_votes && volume.votes[index] > best_votes) {
          best_votes = volume.votes[index];
          best.cell_centre = volume.Center((*ijk)[0], (*ijk)[1], (*ijk)[2]);
          found = true;
        }
      }
      if (found) out.push_back(best);
    }
  }
  return out;
}

}  // namespace silnet::aggregator::testing
