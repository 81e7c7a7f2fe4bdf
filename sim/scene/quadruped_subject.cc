#include "sim/scene/quadruped_subject.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "sim/scene/body_frames.h"

namespace silnet::sim {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

enum Part { kBody, kNeck, kHead, kSnout, kTail, kFirstLeg };

}  // namespace

QuadrupedSubject::QuadrupedSubject(const QuadrupedOptions& options,
                                   std::vector<Material>* materials)
    : options_(options), path_(options.path) {
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> coat(0, 2);
  const Vector3d coats[] = {{0.55, 0.38, 0.2}, {0.85, 0.8, 0.7}, {0.2, 0.18, 0.16}};
  Material fur;
  fur.albedo = coats[coat(rng)];
  fur.second = fur.albedo * 0.55;
  fur.noise_amplitude = 0.2;
  fur.noise_scale = 0.06;
  fur.seed = static_cast<uint32_t>(rng());
  fur_ = AddMaterial(materials, fur);
  Material dark;
  dark.albedo = {0.06, 0.05, 0.05};
  dark.second = {0.15, 0.12, 0.1};
  dark.seed = static_cast<uint32_t>(rng());
  dark_ = AddMaterial(materials, dark);
}

const std::vector<std::string>& QuadrupedSubject::PartNames() const {
  static const std::vector<std::string> names = {"body",
                                                 "neck",
                                                 "head",
                                                 "snout",
                                                 "tail",
                                                 "front_left_upper",
                                                 "front_left_lower",
                                                 "front_right_upper",
                                                 "front_right_lower",
                                                 "hind_left_upper",
                                                 "hind_left_lower",
                                                 "hind_right_upper",
                                                 "hind_right_lower"};
  return names;
}

void QuadrupedSubject::AppendPrimitives(double time, std::vector<Primitive>* out) const {
  const WalkState state = path_.At(time);
  const double s = options_.size * 0.75;
  const double g = std::clamp(state.speed / 1.0, 0.0, 1.2);
  const double phase = 2.0 * kPi * state.distance / (1.1 * s);
  const Matrix3d body = RotationZ(state.heading);
  const Vector3d origin(state.position.x(), state.position.y(), 0.0);
  const Vector3d forward = body.col(0);
  auto world = [&](const Vector3d& p) -> Vector3d { return body * p + origin; };
  auto capsule = [&](const Vector3d& a, const Vector3d& b, double r, int part, int material) {
    const Vector3d wa = world(a), wb = world(b);
    out->push_back(
        Primitive::MakeCapsule(wa, wb, r * s, FrameAlong(wb - wa, forward), part, material));
  };

  const double upper = 0.25 * s, lower = 0.27 * s;
  const double body_height = 0.05 * s + upper + lower;
  const double bob = 0.015 * s * g * std::cos(2.0 * phase);
  const double h = body_height + bob;
  out->push_back(Primitive::MakeEllipsoid(world({0.0, 0.0, h + 0.03 * s}),
                                          Vector3d(0.38, 0.14, 0.15) * s, body, kBody, fur_));
  // Legs in a trot: diagonal pairs move together.
  const double leg_x[4] = {0.26 * s, 0.26 * s, -0.27 * s, -0.27 * s};
  const double leg_y[4] = {0.09 * s, -0.09 * s, 0.09 * s, -0.09 * s};
  const double leg_phase[4] = {0.0, kPi, kPi, 0.0};
  for (int leg = 0; leg < 4; ++leg) {
    const double p = phase + leg_phase[leg];
    const double swing = 0.45 * g * std::sin(p);
    const double lift = 0.7 * g * std::pow(std::max(0.0, std::cos(p)), 2.0);
    const bool front = leg < 2;
    const Vector3d hip(leg_x[leg], leg_y[leg], h);
    const Vector3d knee = hip + upper * Vector3d(std::sin(swing), 0.0, -std::cos(swing));
    const double lower_angle = swing + (front ? -1.0 : 1.0) * (0.15 + lift);
    const Vector3d paw =
        knee + lower * Vector3d(std::sin(lower_angle), 0.0, -std::cos(lower_angle));
    capsule(hip, knee, 0.055, kFirstLeg + 2 * leg, fur_);
    capsule(knee, paw, 0.04, kFirstLeg + 2 * leg + 1, fur_);
  }
  const Vector3d neck_base(0.3 * s, 0.0, h + 0.06 * s);
  const Vector3d neck_top(0.45 * s, 0.0, h + 0.24 * s);
  capsule(neck_base, neck_top, 0.075, kNeck, fur_);
  const double look = 0.3 * std::sin(0.8 * time + options_.seed % 7);
  const Matrix3d head_axes = RotationZ(look);
  const Vector3d head = neck_top + Vector3d(0.05 * s, 0.0, 0.04 * s);
  out->push_back(Primitive::MakeEllipsoid(world(head), Vector3d(0.12, 0.08, 0.085) * s,
                                          body * head_axes, kHead, fur_));
  const Vector3d snout_dir = head_axes * Vector3d(1.0, 0.0, -0.25).normalized();
  capsule(head + 0.06 * s * snout_dir, head + 0.16 * s * snout_dir, 0.04, kSnout, dark_);
  const double wag = 0.5 * std::sin(2.0 * kPi * 2.5 * time);
  capsule({-0.36 * s, 0.0, h + 0.07 * s}, {-0.56 * s, 0.12 * s * std::sin(wag), h + 0.22 * s},
          0.028, kTail, fur_);
}

}  // namespace silnet::sim
