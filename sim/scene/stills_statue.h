#pragma once
// The still subject of simulated stereo stills (`silnet-sim stills`): a stone figure of
// about 18 capsules and ellipsoids standing on the floor at the origin, posed to hold the
// cases that make multi-view stereo hard (thesis ch. 6):
//   * a through-hole: the left hand rests on the hip with the elbow out, so upper arm,
//     forearm, hand, pelvis and chest close a loop around an empty window; the arm touches
//     the body only at the shoulder and the hand;
//   * a thin part: a staff of 12 mm radius (about 4 px across at the default stills
//     distance) from the floor to above the head, gripped by the right fist in front of the
//     body and touching nothing else;
//   * concavities: the stride (between the legs), the arm loop, armpits, neck and waist;
//   * T-junctions: the forward right forearm crosses the chest's outline and the staff the
//     body's and the forward foot's outlines in side views, one leg the other in side views.

#include <cstdint>

#include "sim/scene/subject.h"

namespace silnet::sim {

// Parameters of the stills statue.
struct StillsStatueOptions {
  double height = 1.75;  // metres, floor to the top of the head (the staff reaches 1.95 x scale)
  double heading = 0.0;  // radians about z; 0 faces +x
  uint64_t seed = 1;     // the stone texture
};

// A static figure with a hand on its hip and a staff.
class StillsStatue : public Subject {
 public:
  // Registers the stone material in `materials`.
  StillsStatue(const StillsStatueOptions& options, std::vector<Material>* materials);

  // The same primitives at every time.
  void AppendPrimitives(double time, std::vector<Primitive>* out) const override;
  const std::vector<std::string>& PartNames() const override;
  std::string Kind() const override { return "stills-statue"; }

 private:
  StillsStatueOptions options_;
  int stone_ = 0;
};

}  // namespace silnet::sim
