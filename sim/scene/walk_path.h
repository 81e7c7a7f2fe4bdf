#pragma once
// Where a walking subject is on the floor at any time: a smooth wandering path (a sum of
// sinusoids confined to a disc), the heading the subject turns towards its walking
// direction, its speed and the distance walked (which drives the gait phase).
// Precomputed on a 200 Hz table and linearly interpolated, so any time — including the
// sub-frame exposure times of unsynchronised cameras — is answered consistently.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace silnet::sim {

// Parameters of a wandering path.
struct WalkPathOptions {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  // metres, floor plane
  double radius = 1.3;      // the path stays within this distance of `center`
  double mean_speed = 0.9;  // metres per second, on average
  double time_begin = 0.0;  // seconds; the table covers [time_begin, time_end]
  double time_end = 30.0;
  uint64_t seed = 1;
};

// The state of a walker at one time.
struct WalkState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double heading = 0.0;   // radians, direction the body faces, from +X towards +Y
  double speed = 0.0;     // metres per second
  double distance = 0.0;  // metres walked since time_begin
};

// A precomputed wandering path. Times outside the table are clamped to its ends.
class WalkPath {
 public:
  explicit WalkPath(const WalkPathOptions& options);
  WalkState At(double time) const;

 private:
  Eigen::Vector2d Position(double time) const;
  Eigen::Vector2d Velocity(double time) const;

  WalkPathOptions options_;
  struct Wave {
    double amplitude, omega_x, phase_x, omega_y, phase_y;
  };
  std::vector<Wave> waves_;
  double step_ = 0.005;
  std::vector<WalkState> table_;
};

}  // namespace silnet::sim
