#pragma once
// Simulated camera networks: N cameras in a ring, dome or arc around the capture area,
// each with its own intrinsics (focal length, principal point, optional radial distortion),
// its own frame rate and its own sub-frame time offset.

#include <cstdint>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::sim {

enum class RigLayout {
  kRing,  // one ring at roughly head height
  kDome,  // two or three rings at rising elevations
  kArc,   // a 160-degree arc on one side
};

// Parses "ring", "dome" or "arc"; throws InputError otherwise.
RigLayout ParseRigLayout(const std::string& name);
std::string ToString(RigLayout layout);

// Parameters of a simulated network.
struct CameraNetworkOptions {
  int cameras = 8;
  RigLayout layout = RigLayout::kRing;
  int width = 640;
  int height = 480;
  double radius = 4.5;               // metres from the centre of the capture area
  double target_height = 0.95;       // metres; the cameras aim at (0, 0, target_height)
  double aim_jitter = 0.25;          // aim points uniform within +-this (m), +-0.6x vertically
  double horizontal_fov_deg = 50.0;  // nominal field of view
  double focal_spread = 0.08;        // relative spread of focal lengths (uniform +-)
  double principal_spread = 0.02;    // principal point offset, fraction of the image size
  double max_distortion = 0.0;       // |k1| up to this (k2 = -k1 / 4); 0 = no distortion
  double fps = 30.0;                 // nominal frame rate
  double fps_spread = 0.0;           // relative spread of frame rates (0 = all equal)
  double max_offset = 15.0;          // time offsets uniform in [-max_offset, max_offset] frames
  uint64_t seed = 1;
};

// Builds the cameras (ids cam00, cam01, ...). Throws InputError for impossible options
// (fewer than 2 cameras, non-positive size, fov outside (10, 170) degrees, ...).
std::vector<CameraModel> MakeCameraNetwork(const CameraNetworkOptions& options);

// A camera knocked out of place during a capture: from frame `frame` on, it is turned by
// `rotation_deg` about `axis` and its centre shifted by `shift` (metres), both in the
// camera's coordinates before the move. Its intrinsics and clock stay as they were.
struct CameraMove {
  int camera = 0;
  int frame = 0;
  double rotation_deg = 0.0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
};

// `camera` after `move`.
CameraModel MovedCamera(const CameraModel& camera, const CameraMove& move);

// Parses "cam03@560:2.5[:0.05]": camera cam03 turns 2.5 degrees about its vertical axis
// (a pan) at frame 560 and, optionally, shifts 0.05 m sideways. Throws InputError for
// another form or a camera outside 0..cameras-1.
CameraMove ParseCameraMove(const std::string& text, int cameras);

// Camera id of index i ("cam00").
std::string CameraId(int index);

}  // namespace silnet::sim
