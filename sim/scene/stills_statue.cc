#include "sim/scene/stills_statue.h"

#include <random>

#include "sim/scene/body_frames.h"
#include "sim/scene/body_parts.h"

namespace silnet::sim {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

}  // namespace

StillsStatue::StillsStatue(const StillsStatueOptions& options, std::vector<Material>* materials)
    : options_(options) {
  std::mt19937_64 rng(options.seed);
  Material stone;
  stone.albedo = {0.62, 0.6, 0.55};
  stone.second = {0.3, 0.28, 0.26};
  stone.noise_amplitude = 0.35;
  stone.noise_scale = 0.04;
  stone.seed = static_cast<uint32_t>(rng());
  stone_ = AddMaterial(materials, stone);
}

const std::vector<std::string>& StillsStatue::PartNames() const {
  static const std::vector<std::string> names = {
      "head",           "hair",         "neck",      "chest",           "pelvis",
      "left_upper_arm", "left_forearm", "left_hand", "right_upper_arm", "right_forearm",
      "right_hand",     "left_thigh",   "left_shin", "left_foot",       "right_thigh",
      "right_shin",     "right_foot",   "staff"};
  return names;
}

void StillsStatue::AppendPrimitives(double /*time*/, std::vector<Primitive>* out) const {
  // Model coordinates for a 1.75 m figure facing +x with its left side towards +y.
  const double s = options_.height / 1.75;
  const Matrix3d body = RotationZ(options_.heading);
  const Vector3d forward = body.col(0);
  auto capsule = [&](const Vector3d& a, const Vector3d& b, double r, int part) {
    const Vector3d wa = body * (s * a), wb = body * (s * b);
    out->push_back(
        Primitive::MakeCapsule(wa, wb, s * r, FrameAlong(wb - wa, forward), part, stone_));
  };
  auto ellipsoid = [&](const Vector3d& c, const Vector3d& radii, const Matrix3d& axes, int part) {
    out->push_back(Primitive::MakeEllipsoid(body * (s * c), s * radii, body * axes, part, stone_));
  };

  // Head turned 20 degrees to its left; hair a second, offset ellipsoid.
  const Matrix3d head_axes = RotationZ(0.35);
  const Vector3d head(0.035, 0.0, 1.63);
  ellipsoid(head, {0.1, 0.08, 0.115}, head_axes, kHead);
  ellipsoid(head + head_axes * Vector3d(-0.018, 0.0, 0.03), {0.097, 0.084, 0.1}, head_axes, kHair);
  capsule({0.02, 0.0, 1.44}, {0.03, 0.0, 1.53}, 0.05, kNeck);
  const Vector3d chest(0.02, 0.0, 1.3);
  ellipsoid(chest, {0.115, 0.18, 0.22}, Matrix3d::Identity(), kChest);
  ellipsoid({0.0, 0.0, 0.98}, {0.11, 0.17, 0.13}, Matrix3d::Identity(), kPelvis);

  // Left arm akimbo: elbow out and back, the hand flat on the hip. Only the shoulder and the
  // hand touch the body, so the arm and the torso frame a through-hole.
  const Vector3d left_shoulder(0.02, 0.19, 1.44), left_elbow(-0.05, 0.4, 1.22);
  const Vector3d left_wrist(-0.02, 0.215, 1.015);
  capsule(left_shoulder, left_elbow, 0.046, kLeftUpperArm);
  capsule(left_elbow, left_wrist, 0.038, kLeftForearm);
  ellipsoid({0.03, 0.185, 0.985}, {0.075, 0.025, 0.045}, Matrix3d::Identity(), kLeftHand);

  // Right arm forward, the fist around a staff standing on the floor in front of the body.
  const Vector3d right_shoulder(0.02, -0.19, 1.44), right_elbow(0.16, -0.3, 1.22);
  const Vector3d right_wrist(0.38, -0.33, 1.28);
  capsule(right_shoulder, right_elbow, 0.046, kRightUpperArm);
  capsule(right_elbow, right_wrist, 0.038, kRightForearm);
  const Vector3d fore_dir = (right_wrist - right_elbow).normalized();
  const Vector3d fist = right_wrist + 0.06 * fore_dir;
  const Vector3d staff_foot(fist.x() + 0.03, fist.y() - 0.02, 0.015);
  const Vector3d staff_dir = (fist - staff_foot).normalized();
  const Vector3d staff_top = staff_foot + ((1.95 - staff_foot.z()) / staff_dir.z()) * staff_dir;
  ellipsoid(fist, {0.045, 0.04, 0.055}, FrameAlong(staff_dir, fore_dir), kRightHand);
  capsule(staff_foot, staff_top, 0.012, kStaff);

  // Legs in a stride, the left one forward; feet flat on the floor.
  const Vector3d left_hip(0.0, 0.09, 0.93), left_knee(0.17, 0.1, 0.52), left_ankle(0.2, 0.11, 0.08);
  capsule(left_hip, left_knee, 0.072, kLeftThigh);
  capsule(left_knee, left_ankle, 0.052, kLeftShin);
  capsule({0.18, 0.11, 0.055}, {0.36, 0.11, 0.04}, 0.04, kLeftFoot);
  const Vector3d right_hip(0.0, -0.09, 0.93), right_knee(-0.08, -0.11, 0.51);
  const Vector3d right_ankle(-0.2, -0.12, 0.09);
  capsule(right_hip, right_knee, 0.072, kRightThigh);
  capsule(right_knee, right_ankle, 0.052, kRightShin);
  capsule({-0.22, -0.12, 0.06}, {-0.05, -0.13, 0.04}, 0.04, kRightFoot);
}

}  // namespace silnet::sim
