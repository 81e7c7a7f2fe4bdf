#pragma once
// An articulated human-like figure (about 16 capsules and ellipsoids) that walks a
// wandering path with a speed-dependent gait, counter-rotates its torso, swings its arms,
// raises one or both arms from time to time, and looks around.

#include <cstdint>
#include <memory>

#include "sim/scene/subject.h"
#include "sim/scene/walk_path.h"

namespace silnet::sim {

// The joint-level state of the figure at one time.
struct HumanPose {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double heading = 0.0;      // radians
  double gait_phase = 0.0;   // radians
  double gait_amount = 0.0;  // 0 standing .. ~1.2 brisk walk
  double raise_left = 0.0;   // 0 arm down .. 1 arm raised overhead
  double raise_right = 0.0;
  double wave = 0.0;      // forearm waving angle, radians
  double head_yaw = 0.0;  // radians
};

// Parameters of one figure.
struct HumanOptions {
  double height = 1.75;  // metres
  WalkPathOptions path;  // where it walks
  uint64_t seed = 1;     // colours, arm-raise schedule
  bool frozen = false;   // a statue: always `frozen_pose`
  HumanPose frozen_pose;
  bool stone = false;  // one grey, strongly textured material (for stereo)
};

// A walking human-like subject.
class HumanSubject : public Subject {
 public:
  // Registers the figure's materials in `materials`.
  HumanSubject(const HumanOptions& options, std::vector<Material>* materials);

  void AppendPrimitives(double time, std::vector<Primitive>* out) const override;
  const std::vector<std::string>& PartNames() const override;
  std::string Kind() const override { return options_.frozen ? "statue" : "human"; }

  // The pose at reference time `time`.
  HumanPose PoseAt(double time) const;
  // The primitives of a pose (world frame).
  void AppendPosePrimitives(const HumanPose& pose, std::vector<Primitive>* out) const;

 private:
  double RaiseAmount(double time, int arm) const;

  HumanOptions options_;
  std::unique_ptr<WalkPath> path_;
  struct RaiseEvent {
    double start, duration;
    int arms;  // bit 0 left, bit 1 right
  };
  std::vector<RaiseEvent> raises_;
  double head_phase_ = 0.0;
  int skin_ = 0, hair_ = 0, shirt_ = 0, trousers_ = 0, shoes_ = 0;
};

}  // namespace silnet::sim
