#include "aggregator/stereo/lattice_ray.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace silnet::aggregator {

// Where the ray centre + t * direction (t >= 0) is inside `box`: [t_in, t_out], if anywhere.
std::optional<std::pair<double, double>> ClipRay(const WorldBox& box, const Eigen::Vector3d& centre,
                                                 const Eigen::Vector3d& direction) {
  double t_in = 0, t_out = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-15) {
      if (centre[a] < box.min()[a] || centre[a] > box.max()[a]) return std::nullopt;
      continue;
    }
    double t0 = (box.min()[a] - centre[a]) / direction[a];
    double t1 = (box.max()[a] - centre[a]) / direction[a];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  if (t_in >= t_out) return std::nullopt;
  return std::make_pair(t_in, t_out);
}

}  // namespace silnet::aggregator
