#pragma once
// The static surroundings of a simulated capture: a textured room (tiled floor, walls with
// posters and a skirting band, ceiling), one directional light with ambient fill, and
// slow changes of the light's brightness that background segmentation must tolerate.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace silnet::sim {

// Which room surface a ray hit.
enum class RoomSurface { kFloor, kWall, kCeiling };

// What a ray from inside the room sees.
struct RoomHit {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d albedo = Eigen::Vector3d::Constant(0.5);  // RGB [0, 1]
  RoomSurface surface = RoomSurface::kFloor;
};

// Parameters of the room and light.
struct EnvironmentOptions {
  double half_size = 8.0;  // the room is [-half_size, half_size]^2 on the floor
  double height = 6.0;     // metres
  bool lighting_changes = true;
  uint64_t seed = 1;
};

// A textured room lit by one directional light.
class Environment {
 public:
  explicit Environment(const EnvironmentOptions& options);

  // The surface seen along unit direction `dir` from `origin` (which must be in the room).
  RoomHit Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const;
  // Radiance factor of a lit surface with `normal`: ambient + diffuse * max(0, n.l).
  double Shading(const Eigen::Vector3d& normal) const;
  // Radiance factor in the shadow of the subject: ambient only.
  double ambient() const { return ambient_; }
  // Unit vector pointing towards the light.
  const Eigen::Vector3d& light_direction() const { return light_direction_; }
  // Brightness of the light at reference time `time` (1 = nominal; varies a few percent).
  double LightGain(double time) const;
  const EnvironmentOptions& options() const { return options_; }

 private:
  Eigen::Vector3d FloorAlbedo(const Eigen::Vector3d& p) const;
  Eigen::Vector3d WallAlbedo(int wall, const Eigen::Vector3d& p, double along) const;

  struct Poster {
    int wall;
    double u0, u1, z0, z1;
    Eigen::Vector3d colour, second;
  };
  EnvironmentOptions options_;
  Eigen::Vector3d light_direction_;
  double ambient_ = 0.45;
  double diffuse_ = 0.6;
  Eigen::Vector3d floor_colour_, wall_colours_[4];
  std::vector<Poster> posters_;
  double gain_phase_[2] = {0.0, 0.0};
  uint32_t texture_seed_ = 1;
};

}  // namespace silnet::sim
