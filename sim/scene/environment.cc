#include "sim/scene/environment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "sim/scene/solid_texture.h"

namespace silnet::sim {
namespace {

// A pseudo-random value in [0, 1] per floor tile.
double TileValue(int32_t x, int32_t y, uint32_t seed) {
  return ValueNoise(Eigen::Vector3d(x, y, 0.0), seed);
}

}  // namespace

Environment::Environment(const EnvironmentOptions& options) : options_(options) {
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double azimuth = 2.0 * std::numbers::pi * unit(rng);
  const double elevation = (50.0 + 25.0 * unit(rng)) * std::numbers::pi / 180.0;
  light_direction_ = Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                     std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  floor_colour_ = Eigen::Vector3d(0.55, 0.45, 0.33) * (0.8 + 0.4 * unit(rng));
  const Eigen::Vector3d palette[] = {{0.75, 0.72, 0.65}, {0.55, 0.62, 0.7}, {0.7, 0.6, 0.5},
                                     {0.5, 0.6, 0.5},    {0.8, 0.78, 0.74}, {0.62, 0.55, 0.66}};
  for (auto& c : wall_colours_)
    c = palette[static_cast<size_t>(unit(rng) * 6.0) % 6];
  for (int wall = 0; wall < 4; ++wall) {
    const int count = 2 + static_cast<int>(unit(rng) * 3.0);
    for (int i = 0; i < count; ++i) {
      Poster p;
      p.wall = wall;
      const double width = 0.6 + 1.2 * unit(rng);
      p.u0 = -options.half_size + 0.5 + (2.0 * options.half_size - 1.0 - width) * unit(rng);
      p.u1 = p.u0 + width;
      p.z0 = 0.6 + 0.8 * unit(rng);
      p.z1 = p.z0 + 0.5 + 1.0 * unit(rng);
      p.colour =
          Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 0.8 + Eigen::Vector3d::Constant(0.1);
      p.second =
          Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 0.8 + Eigen::Vector3d::Constant(0.1);
      posters_.push_back(p);
    }
  }
  gain_phase_[0] = 2.0 * std::numbers::pi * unit(rng);
  gain_phase_[1] = 2.0 * std::numbers::pi * unit(rng);
  texture_seed_ = static_cast<uint32_t>(rng());
}

double Environment::Shading(const Eigen::Vector3d& normal) const {
  return ambient_ + diffuse_ * std::max(0.0, normal.dot(light_direction_));
}

double Environment::LightGain(double time) const {
  if (!options_.lighting_changes) return 1.0;
  return 1.0 + 0.05 * std::sin(2.0 * std::numbers::pi * time / 9.0 + gain_phase_[0]) +
         0.025 * std::sin(2.0 * std::numbers::pi * time / 3.1 + gain_phase_[1]);
}

Eigen::Vector3d Environment::FloorAlbedo(const Eigen::Vector3d& p) const {
  const double tile = 0.5;
  const double tx = p.x() / tile, ty = p.y() / tile;
  const double fx = tx - std::floor(tx), fy = ty - std::floor(ty);
  const double grout = 0.03;
  if (fx < grout || fy < grout) return floor_colour_ * 0.35;
  const double tile_shade =
      0.8 + 0.4 * TileValue(static_cast<int32_t>(std::floor(tx)),
                            static_cast<int32_t>(std::floor(ty)), texture_seed_);
  const double grain = FractalNoise(p, 0.08, 3, texture_seed_ + 1);
  return floor_colour_ * tile_shade * (0.8 + 0.4 * grain);
}

Eigen::Vector3d Environment::WallAlbedo(int wall, const Eigen::Vector3d& p, double along) const {
  if (p.z() < 0.15) return wall_colours_[wall] * 0.3;
  for (const Poster& poster : posters_) {
    if (poster.wall == wall && along >= poster.u0 && along <= poster.u1 && p.z() >= poster.z0 &&
        p.z() <= poster.z1) {
      const double n = FractalNoise(p, 0.12, 3, texture_seed_ + 7 + static_cast<uint32_t>(wall));
      return poster.colour + (poster.second - poster.colour) * std::clamp(2.0 * n - 0.5, 0.0, 1.0);
    }
  }
  const double n = FractalNoise(p, 0.4, 4, texture_seed_ + 3);
  return wall_colours_[wall] * (0.85 + 0.3 * n);
}

RoomHit Environment::Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const {
  const double inf = std::numeric_limits<double>::infinity();
  const double h = options_.half_size;
  double best = inf;
  int plane = -1;  // 0 floor, 1 ceiling, 2..5 walls (+x, -x, +y, -y)
  auto consider = [&](double t, int id) {
    if (t > 0.0 && t < best) {
      best = t;
      plane = id;
    }
  };
  if (dir.z() < 0) consider(-origin.z() / dir.z(), 0);
  if (dir.z() > 0) consider((options_.height - origin.z()) / dir.z(), 1);
  if (dir.x() > 0) consider((h - origin.x()) / dir.x(), 2);
  if (dir.x() < 0) consider((-h - origin.x()) / dir.x(), 3);
  if (dir.y() > 0) consider((h - origin.y()) / dir.y(), 4);
  if (dir.y() < 0) consider((-h - origin.y()) / dir.y(), 5);
  RoomHit hit;
  if (plane < 0) return hit;
  hit.point = origin + best * dir;
  switch (plane) {
    case 0:
      hit.surface = RoomSurface::kFloor;
      hit.normal = Eigen::Vector3d::UnitZ();
      hit.albedo = FloorAlbedo(hit.point);
      break;
    case 1:
      hit.surface = RoomSurface::kCeiling;
      hit.normal = -Eigen::Vector3d::UnitZ();
      hit.albedo = Eigen::Vector3d::Constant(0.8) *
                   (0.9 + 0.2 * FractalNoise(hit.point, 0.5, 2, texture_seed_ + 5));
      break;
    default: {
      const int wall = plane - 2;
      hit.surface = RoomSurface::kWall;
      const double along = wall < 2 ? hit.point.y() : hit.point.x();
      hit.normal = Eigen::Vector3d::Zero();
      hit.normal[wall < 2 ? 0 : 1] = (wall % 2 == 0) ? -1.0 : 1.0;
      hit.albedo = WallAlbedo(wall, hit.point, along);
    }
  }
  return hit;
}

}  // namespace silnet::sim
