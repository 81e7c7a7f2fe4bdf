#include "sim/scene/walk_path.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace silnet::sim {
namespace {

double WrapAngle(double a) {
  return std::remainder(a, 2.0 * std::numbers::pi);
}

}  // namespace

WalkPath::WalkPath(const WalkPathOptions& options) : options_(options) {
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Three waves whose amplitudes sum to the radius (per axis, divided by sqrt 2 so the path
  // stays in the disc), with random frequencies scaled so the RMS speed is mean_speed.
  const double weights[3] = {0.55, 0.3, 0.15};
  double mean_square_speed = 0.0;
  for (double w : weights) {
    Wave wave;
    wave.amplitude = w * options.radius / std::numbers::sqrt2;
    wave.omega_x = 0.6 + 0.8 * unit(rng);
    wave.omega_y = wave.omega_x * (0.8 + 0.4 * unit(rng));
    wave.phase_x = 2.0 * std::numbers::pi * unit(rng);
    wave.phase_y = 2.0 * std::numbers::pi * unit(rng);
    mean_square_speed += 0.5 * wave.amplitude * wave.amplitude *
                         (wave.omega_x * wave.omega_x + wave.omega_y * wave.omega_y);
    waves_.push_back(wave);
  }
  if (mean_square_speed > 0.0) {
    const double scale = options.mean_speed / std::sqrt(mean_square_speed);
    for (Wave& wave : waves_) {
      wave.omega_x *= scale;
      wave.omega_y *= scale;
    }
  }
  // Integrate heading and distance at 1 kHz, store every step_.
  const double begin = options.time_begin;
  const int samples =
      std::max(2, static_cast<int>(std::ceil((options.time_end - begin) / step_)) + 1);
  table_.reserve(static_cast<size_t>(samples));
  const int substeps = 5;
  const double dt = step_ / substeps;
  Eigen::Vector2d v0 = Velocity(begin);
  double heading = v0.norm() > 1e-9 ? std::atan2(v0.y(), v0.x()) : 0.0;
  double distance = 0.0;
  for (int i = 0; i < samples; ++i) {
    const double time = begin + i * step_;
    if (i > 0) {
      for (int s = 0; s < substeps; ++s) {
        const double tm = time - step_ + (s + 0.5) * dt;
        const Eigen::Vector2d v = Velocity(tm);
        const double speed = v.norm();
        distance += speed * dt;
        if (speed > 1e-6) {
          // Turn towards the walking direction, faster when walking faster.
          const double error = WrapAngle(std::atan2(v.y(), v.x()) - heading);
          const double gain = 6.0 * std::min(1.0, speed / 0.4);
          heading += std::clamp(gain * error, -4.0, 4.0) * dt;
        }
      }
    }
    WalkState state;
    state.position = Position(time);
    state.heading = heading;
    state.speed = Velocity(time).norm();
    state.distance = distance;
    table_.push_back(state);
  }
}

Eigen::Vector2d WalkPath::Position(double time) const {
  Eigen::Vector2d p = options_.center;
  for (const Wave& w : waves_) {
    p.x() += w.amplitude * std::sin(w.omega_x * time + w.phase_x);
    p.y() += w.amplitude * std::sin(w.omega_y * time + w.phase_y);
  }
  return p;
}

Eigen::Vector2d WalkPath::Velocity(double time) const {
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  for (const Wave& w : waves_) {
    v.x() += w.amplitude * w.omega_x * std::cos(w.omega_x * time + w.phase_x);
    v.y() += w.amplitude * w.omega_y * std::cos(w.omega_y * time + w.phase_y);
  }
  return v;
}

WalkState WalkPath::At(double time) const {
  const double u =
      std::clamp((time - options_.time_begin) / step_, 0.0, static_cast<double>(table_.size() - 1));
  const auto i = std::min(static_cast<size_t>(u), table_.size() - 2);
  const double f = u - static_cast<double>(i);
  const WalkState& s0 = table_[i];
  const WalkState& s1 = table_[i + 1];
  WalkState out;
  const double clamped = options_.time_begin + u * step_;
  out.position = Position(clamped);
  out.heading = s0.heading + f * (s1.heading - s0.heading);
  out.speed = Velocity(clamped).norm();
  out.distance = s0.distance + f * (s1.distance - s0.distance);
  return out;
}

}  // namespace silnet::sim
