#pragma once
// The parts of a posed human figure, as its primitives' part ids.

namespace silnet::sim {

// The human subject's and the statue's parts (only the statue holds a staff).
enum BodyPart {
  kHead,
  kHair,
  kNeck,
  kChest,
  kPelvis,
  kLeftUpperArm,
  kLeftForearm,
  kLeftHand,
  kRightUpperArm,
  kRightForearm,
  kRightHand,
  kLeftThigh,
  kLeftShin,
  kLeftFoot,
  kRightThigh,
  kRightShin,
  kRightFoot,
  kStaff,
};

}  // namespace silnet::sim
