#include "sim/camera_network.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <regex>

#include "shared/util/check.h"

namespace silnet::sim {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

struct Placement {
  double azimuth;    // radians
  double elevation;  // radians above the horizontal through the target
};

std::vector<Placement> PlaceCameras(const CameraNetworkOptions& o, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  std::vector<Placement> placements;
  const int n = o.cameras;
  switch (o.layout) {
    case RigLayout::kRing:
      for (int i = 0; i < n; ++i) {
        placements.push_back({2.0 * std::numbers::pi * i / n + 0.08 * jitter(rng),
                              (8.0 + 6.0 * jitter(rng)) * kDegree});
      }
      break;
    case RigLayout::kArc:
      for (int i = 0; i < n; ++i) {
        const double u = n > 1 ? static_cast<double>(i) / (n - 1) : 0.5;
        placements.push_back({(-80.0 + 160.0 * u) * kDegree + 0.04 * jitter(rng),
                              (10.0 + 6.0 * jitter(rng)) * kDegree});
      }
      break;
    case RigLayout::kDome: {
      // Rings at rising elevations; lower rings get more cameras.
      const double elevations[3] = {8.0, 32.0, 56.0};
      const double weights[3] = {0.45, 0.35, 0.2};
      int assigned = 0;
      for (int ring = 0; ring < 3; ++ring) {
        const int count =
            ring == 2 ? n - assigned : static_cast<int>(std::round(weights[ring] * n));
        const double start = ring * 0.7;
        for (int i = 0; i < count; ++i) {
          placements.push_back({start + 2.0 * std::numbers::pi * i / count + 0.05 * jitter(rng),
                                (elevations[ring] + 4.0 * jitter(rng)) * kDegree});
        }
        assigned += count;
      }
      break;
    }
  }
  return placements;
}

}  // namespace

RigLayout ParseRigLayout(const std::string& name) {
  if (name == "ring") return RigLayout::kRing;
  if (name == "dome") return RigLayout::kDome;
  if (name == "arc") return RigLayout::kArc;
  throw InputError("unknown layout '" + name + "' (use ring, dome or arc)");
}

std::string ToString(RigLayout layout) {
  switch (layout) {
    case RigLayout::kRing:
      return "ring";
    case RigLayout::kDome:
      return "dome";
    case RigLayout::kArc:
      return "arc";
  }
  return "unknown";
}

CameraModel MovedCamera(const CameraModel& camera, const CameraMove& move) {
  CameraModel moved = camera;
  const Eigen::Vector3d centre = camera.Center() + camera.R.transpose() * move.shift;
  moved.R = Eigen::AngleAxisd(move.rotation_deg * std::numbers::pi / 180.0, move.axis.normalized())
                .toRotationMatrix() *
            camera.R;
  moved.t = -moved.R * centre;
  return moved;
}

CameraMove ParseCameraMove(const std::string& text, int cameras) {
  static const std::regex pattern(R"(cam(\d{2,3})@(\d+):([-+]?[0-9.]+)(?::([-+]?[0-9.]+))?)");
  std::smatch match;
  if (!std::regex_match(text, match, pattern)) {
    throw InputError("a camera move looks like cam03@560:2.5 or cam03@560:2.5:0.05, not '" + text +
                     "'");
  }
  CameraMove move;
  move.camera = std::stoi(match[1]);
  if (move.camera >= cameras)
    throw InputError(fmt::format("camera move '{}': there are only {} cameras", text, cameras));
  move.frame = std::stoi(match[2]);
  move.rotation_deg = std::stod(match[3]);
  move.axis = Eigen::Vector3d::UnitY();
  if (match[4].matched) move.shift = Eigen::Vector3d(std::stod(match[4]), 0.0, 0.0);
  return move;
}

std::string CameraId(int index) {
  return fmt::format("cam{:02d}", index);
}

std::vector<CameraModel> MakeCameraNetwork(const CameraNetworkOptions& o) {
  if (o.cameras < 2) throw InputError("a camera network needs at least 2 cameras");
  if (o.cameras > 100) throw InputError("at most 100 simulated cameras");
  if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192) {
    throw InputError(fmt::format("image size {}x{} is out of range", o.width, o.height));
  }
  if (!(o.horizontal_fov_deg > 10.0 && o.horizontal_fov_deg < 170.0)) {
    throw InputError("field of view must lie between 10 and 170 degrees");
  }
  if (!(o.fps > 0.0)) throw InputError("fps must be positive");
  if (!(o.radius > 0.5)) throw InputError("rig radius must exceed 0.5 m");
  if (!(o.target_height >= 0.0 && o.target_height < 10.0)) {
    throw InputError("target height must lie between 0 and 10 m");
  }
  if (!(o.aim_jitter >= 0.0 && o.aim_jitter <= 1.0)) throw InputError("aim jitter must be 0..1 m");
  if (o.max_offset < 0.0 || o.fps_spread < 0.0 || o.fps_spread >= 0.5 || o.max_distortion < 0.0 ||
      o.max_distortion > 0.3) {
    throw InputError("offset, fps spread or distortion out of range");
  }
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  const std::vector<Placement> placements = PlaceCameras(o, rng);
  const Eigen::Vector3d target(0.0, 0.0, o.target_height);
  const double nominal_focal = 0.5 * o.width / std::tan(0.5 * o.horizontal_fov_deg * kDegree);
  std::vector<CameraModel> cameras;
  for (int i = 0; i < o.cameras; ++i) {
    const Placement& p = placements[static_cast<size_t>(i)];
    CameraModel c;
    c.id = CameraId(i);
    c.width = o.width;
    c.height = o.height;
    const double focal = nominal_focal * (1.0 + o.focal_spread * jitter(rng));
    c.K << focal, 0.0, 0.5 * (o.width - 1) + o.principal_spread * o.width * jitter(rng), 0.0, focal,
        0.5 * (o.height - 1) + o.principal_spread * o.height * jitter(rng), 0.0, 0.0, 1.0;
    if (o.max_distortion > 0.0) {
      const double k1 = o.max_distortion * jitter(rng);
      c.dist << k1, -0.25 * k1, 0.0, 0.0, 0.0;
    }
    const double radius = o.radius * (1.0 + 0.05 * jitter(rng));
    const Eigen::Vector3d center =
        target + radius * Eigen::Vector3d(std::cos(p.elevation) * std::cos(p.azimuth),
                                          std::cos(p.elevation) * std::sin(p.azimuth),
                                          std::sin(p.elevation));
    // Drawn z, y, x: the order in which earlier releases drew them, so seeds keep their cameras.
    const double az = jitter(rng), ay = jitter(rng), ax = jitter(rng);
    const Eigen::Vector3d aim = target + o.aim_jitter * Eigen::Vector3d(ax, ay, 0.6 * az);
    const Eigen::Matrix3d look = LookAtRotation(center, aim, Eigen::Vector3d::UnitZ());
    const double roll = 2.0 * kDegree * jitter(rng);
    Eigen::Matrix3d roll_matrix;
    roll_matrix << std::cos(roll), -std::sin(roll), 0.0, std::sin(roll), std::cos(roll), 0.0, 0.0,
        0.0, 1.0;
    c.R = roll_matrix * look;
    c.t = -c.R * center;
    c.fps = o.fps * (1.0 + o.fps_spread * jitter(rng));
    c.time_offset = o.max_offset * jitter(rng);
    cameras.push_back(c);
  }
  return cameras;
}

}  // namespace silnet::sim
