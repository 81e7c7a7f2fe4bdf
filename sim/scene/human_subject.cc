#include "sim/scene/human_subject.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "sim/scene/body_frames.h"
#include "sim/scene/body_parts.h"

namespace silnet::sim {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

double SmoothStep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

Eigen::Vector3d Pick(std::mt19937_64& rng, std::initializer_list<Eigen::Vector3d> options) {
  std::uniform_int_distribution<size_t> index(0, options.size() - 1);
  return *(options.begin() + static_cast<std::ptrdiff_t>(index(rng)));
}

Eigen::Vector3d HsvToRgb(double h, double s, double v) {
  const double c = v * s;
  const double hp = std::fmod(h * 6.0, 6.0);
  const double x = c * (1.0 - std::abs(std::fmod(hp, 2.0) - 1.0));
  Eigen::Vector3d rgb;
  if (hp < 1)
    rgb = {c, x, 0};
  else if (hp < 2)
    rgb = {x, c, 0};
  else if (hp < 3)
    rgb = {0, c, x};
  else if (hp < 4)
    rgb = {0, x, c};
  else if (hp < 5)
    rgb = {x, 0, c};
  else
    rgb = {c, 0, x};
  return rgb + Eigen::Vector3d::Constant(v - c);
}

}  // namespace

HumanSubject::HumanSubject(const HumanOptions& options, std::vector<Material>* materials)
    : options_(options) {
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto material = [&](Eigen::Vector3d albedo, Eigen::Vector3d second, double amplitude,
                      double scale, double stripes) {
    Material m;
    m.albedo = albedo;
    m.second = second;
    m.noise_amplitude = amplitude;
    m.noise_scale = scale;
    m.stripe_period = stripes;
    m.seed = static_cast<uint32_t>(rng());
    return AddMaterial(materials, m);
  };
  if (options.stone) {
    const int stone = material({0.62, 0.6, 0.55}, {0.3, 0.28, 0.26}, 0.35, 0.04, 0.0);
    skin_ = hair_ = shirt_ = trousers_ = shoes_ = stone;
  } else {
    const Vector3d skin =
        Pick(rng, {{0.87, 0.72, 0.6}, {0.7, 0.52, 0.4}, {0.45, 0.32, 0.24}, {0.95, 0.8, 0.7}});
    skin_ = material(skin, skin * 0.85, 0.06, 0.03, 0.0);
    const Vector3d hair =
        Pick(rng, {{0.12, 0.08, 0.05}, {0.05, 0.05, 0.05}, {0.75, 0.6, 0.3}, {0.45, 0.25, 0.12}});
    hair_ = material(hair, hair * 0.6, 0.2, 0.01, 0.0);
    const Vector3d shirt = HsvToRgb(unit(rng), 0.45 + 0.45 * unit(rng), 0.45 + 0.45 * unit(rng));
    const Vector3d shirt_second = HsvToRgb(unit(rng), 0.3 + 0.5 * unit(rng), 0.3 + 0.6 * unit(rng));
    shirt_ =
        material(shirt, shirt_second, 0.12, 0.05, unit(rng) < 0.5 ? 0.06 + 0.06 * unit(rng) : 0.0);
    const Vector3d trousers =
        Pick(rng, {{0.15, 0.2, 0.4}, {0.1, 0.1, 0.1}, {0.6, 0.55, 0.4}, {0.35, 0.35, 0.37}});
    trousers_ = material(trousers, trousers * 0.7, 0.12, 0.04, 0.0);
    shoes_ = material({0.08, 0.07, 0.07}, {0.3, 0.3, 0.3}, 0.1, 0.02, 0.0);
  }
  if (!options.frozen) path_ = std::make_unique<WalkPath>(options.path);
  // Arm raises: one every few seconds, lasting 1.5-3 s, left, right or both.
  double start = options.path.time_begin + 1.0 + 3.0 * unit(rng);
  while (start < options.path.time_end) {
    RaiseEvent event;
    event.start = start;
    event.duration = 1.5 + 1.5 * unit(rng);
    event.arms = 1 + static_cast<int>(unit(rng) * 3.0);
    raises_.push_back(event);
    start += event.duration + 2.0 + 4.0 * unit(rng);
  }
  head_phase_ = 2.0 * kPi * unit(rng);
}

const std::vector<std::string>& HumanSubject::PartNames() const {
  static const std::vector<std::string> names = {
      "head",           "hair",         "neck",      "chest",           "pelvis",
      "left_upper_arm", "left_forearm", "left_hand", "right_upper_arm", "right_forearm",
      "right_hand",     "left_thigh",   "left_shin", "left_foot",       "right_thigh",
      "right_shin",     "right_foot"};
  return names;
}

double HumanSubject::RaiseAmount(double time, int arm) const {
  double amount = 0.0;
  for (const RaiseEvent& e : raises_) {
    if ((e.arms & (1 << arm)) == 0) continue;
    const double up = SmoothStep(e.start, e.start + 0.6, time);
    const double down = 1.0 - SmoothStep(e.start + e.duration - 0.6, e.start + e.duration, time);
    amount = std::max(amount, std::min(up, down));
  }
  return amount;
}

HumanPose HumanSubject::PoseAt(double time) const {
  if (options_.frozen) return options_.frozen_pose;
  const WalkState state = path_->At(time);
  HumanPose pose;
  const double s = options_.height / 1.75;
  pose.position = state.position;
  pose.heading = state.heading;
  pose.gait_phase = 2.0 * kPi * state.distance / (1.45 * s);
  pose.gait_amount = std::clamp(state.speed / 1.1, 0.0, 1.2);
  pose.raise_left = RaiseAmount(time, 0);
  pose.raise_right = RaiseAmount(time, 1);
  pose.wave = 0.5 * std::sin(2.0 * kPi * 1.4 * time);
  pose.head_yaw = 0.35 * std::sin(0.9 * time + head_phase_);
  return pose;
}

void HumanSubject::AppendPrimitives(double time, std::vector<Primitive>* out) const {
  AppendPosePrimitives(PoseAt(time), out);
}

void HumanSubject::AppendPosePrimitives(const HumanPose& pose, std::vector<Primitive>* out) const {
  const double s = options_.height / 1.75;
  const double g = pose.gait_amount;
  const Matrix3d body = RotationZ(pose.heading);
  const Vector3d origin(pose.position.x(), pose.position.y(), 0.0);
  const Vector3d forward = body.col(0);
  auto world = [&](const Vector3d& p) -> Vector3d { return body * p + origin; };
  auto capsule = [&](const Vector3d& a, const Vector3d& b, double r, int part, int material) {
    const Vector3d wa = world(a), wb = world(b);
    out->push_back(
        Primitive::MakeCapsule(wa, wb, r * s, FrameAlong(wb - wa, forward), part, material));
  };
  auto ellipsoid = [&](const Vector3d& c, const Vector3d& radii, const Matrix3d& axes, int part,
                       int material) {
    out->push_back(Primitive::MakeEllipsoid(world(c), radii * s, body * axes, part, material));
  };

  // Legs: hip flexion and knee bend from the gait phase; the hip height keeps the lower
  // foot on the floor, which also gives the vertical bob of walking.
  const double thigh = 0.44 * s, shin = 0.42 * s, ankle_height = 0.075 * s;
  double leg_flexion[2], knee_bend[2], leg_drop[2];
  for (int side = 0; side < 2; ++side) {
    const double phase = pose.gait_phase + (side == 1 ? kPi : 0.0);
    leg_flexion[side] = 0.42 * g * std::sin(phase);
    knee_bend[side] = 0.06 + 1.1 * g * std::pow(std::max(0.0, std::cos(phase)), 2.0);
    leg_drop[side] =
        thigh * std::cos(leg_flexion[side]) + shin * std::cos(leg_flexion[side] - knee_bend[side]);
  }
  const double hip_height = ankle_height + std::max(leg_drop[0], leg_drop[1]);
  for (int side = 0; side < 2; ++side) {
    const double y = side == 0 ? 0.09 * s : -0.09 * s;
    const Vector3d hip(0.0, y, hip_height);
    const Vector3d knee =
        hip + thigh * Vector3d(std::sin(leg_flexion[side]), 0.0, -std::cos(leg_flexion[side]));
    const double shin_angle = leg_flexion[side] - knee_bend[side];
    const Vector3d ankle = knee + shin * Vector3d(std::sin(shin_angle), 0.0, -std::cos(shin_angle));
    const Vector3d heel = ankle + Vector3d(-0.02 * s, 0.0, -0.02 * s);
    const Vector3d toe = ankle + Vector3d(0.16 * s, 0.0, -0.035 * s);
    const int base = side == 0 ? kLeftThigh : kRightThigh;
    capsule(hip, knee, 0.072, base, trousers_);
    capsule(knee, ankle, 0.052, base + 1, trousers_);
    capsule(heel, toe, 0.04, base + 2, shoes_);
  }

  // Torso: pelvis and chest, the chest leaning with speed and counter-rotating to the hips.
  const double twist = 0.15 * g * std::sin(pose.gait_phase);
  const double lean = 0.06 * g;
  const Matrix3d chest_axes = RotationZ(twist) * RotationY(lean);
  ellipsoid({0.0, 0.0, hip_height + 0.07 * s}, {0.11, 0.17, 0.13}, RotationZ(-0.5 * twist), kPelvis,
            trousers_);
  const Vector3d chest(0.02 * s + 0.1 * s * lean, 0.0, hip_height + 0.37 * s);
  ellipsoid(chest, {0.115, 0.18, 0.22}, chest_axes, kChest, shirt_);
  const Vector3d neck_base = chest + chest_axes * Vector3d(0.0, 0.0, 0.17 * s);
  const Vector3d neck_top = neck_base + chest_axes * Vector3d(0.01 * s, 0.0, 0.1 * s);
  capsule(neck_base, neck_top, 0.05, kNeck, skin_);
  const Matrix3d head_axes = RotationZ(pose.head_yaw + twist);
  const Vector3d head = neck_top + Vector3d(0.015 * s, 0.0, 0.1 * s);
  ellipsoid(head, {0.1, 0.08, 0.115}, head_axes, kHead, skin_);
  ellipsoid(head + head_axes * Vector3d(-0.018 * s, 0.0, 0.03 * s), {0.097, 0.084, 0.1}, head_axes,
            kHair, hair_);

  // Arms: swing opposite to the legs, raised sideways during raise events, forearm waving.
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? 1.0 : -1.0;
    const double raise = side == 0 ? pose.raise_left : pose.raise_right;
    const double phase = pose.gait_phase + (side == 0 ? 0.0 : kPi);
    const double swing = -0.35 * g * std::sin(phase);
    const Vector3d shoulder = chest + chest_axes * Vector3d(0.0, sign * 0.19 * s, 0.14 * s);
    const double abduction = 0.12 + 2.5 * raise;
    const double flexion = swing * (1.0 - raise) + 0.3 * raise;
    const Vector3d upper_dir = chest_axes * RotationX(sign * abduction) *
                               Vector3d(std::sin(flexion), 0.0, -std::cos(flexion));
    const Vector3d elbow = shoulder + 0.29 * s * upper_dir;
    const double bend = 0.3 + 0.25 * g + raise * (0.5 + pose.wave);
    const Vector3d towards = raise > 0.5 ? Vector3d(0.3, -sign, 0.8) : Vector3d(1.0, 0.0, 0.3);
    const Vector3d fore_dir = TurnTowards(upper_dir, chest_axes * towards.normalized(), bend);
    const Vector3d wrist = elbow + 0.25 * s * fore_dir;
    const int base = side == 0 ? kLeftUpperArm : kRightUpperArm;
    capsule(shoulder, elbow, 0.046, base, shirt_);
    capsule(elbow, wrist, 0.038, base + 1, skin_);
    ellipsoid(wrist + 0.07 * s * fore_dir, {0.025, 0.045, 0.075},
              FrameAlong(fore_dir, Vector3d::UnitX()), base + 2, skin_);
  }
}

}  // namespace silnet::sim
