#pragma once
// Renders what one simulated camera sees: the exact silhouette of the subjects (a pixel is
// foreground iff the ray through its centre hits a primitive, distortion included) and a
// colour frame — textured, shaded subjects over the textured room, with cast shadows on
// the floor, the light's brightness changes, the camera's exposure and sensor noise.

#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "sim/render/sensor_noise.h"
#include "sim/scene/scene.h"

namespace silnet::sim {

// Rendering options shared by all cameras.
struct RenderSettings {
  double noise_sigma = 2.0;  // sensor noise, DN (0 = clean)
  bool shadows = true;       // cast the subjects' shadows on the floor
  uint64_t seed = 1;         // noise and per-camera exposure
};

// A pixel rectangle [x0, x1) x [y0, y1).
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

// Renders one camera of a scene. Construction precomputes the per-pixel rays and the
// room's appearance; Render is const and safe to call from several threads.
class CameraRenderer {
 public:
  // `noise` may be shared between renderers of equal image size; null draws a table for
  // this camera.
  CameraRenderer(const CameraModel& camera, const Scene& scene, const RenderSettings& settings,
                 int camera_index, std::shared_ptr<const SensorNoise> noise = nullptr);

  // Renders the scene at reference time `time`. `mask` receives CV_8UC1 0/255, `colour`
  // CV_8UC3 BGR; either may be null. `image_seed` selects the sensor noise.
  void Render(double time, uint64_t image_seed, cv::Mat* mask, cv::Mat* colour) const;

  // Renders given world-frame primitives (used by tests to render chosen geometry).
  void RenderPrimitives(const std::vector<Primitive>& world, double light_gain, uint64_t image_seed,
                        cv::Mat* mask, cv::Mat* colour) const;

  const CameraModel& camera() const { return camera_; }

 private:
  PixelBox ProjectedBox(const Eigen::Vector3d& center_cam, double radius) const;
  Eigen::Vector3d Ray(int x, int y) const {
    return rays_[static_cast<size_t>(y) * static_cast<size_t>(camera_.width) +
                 static_cast<size_t>(x)]
        .cast<double>();
  }

  CameraModel camera_;
  const Scene* scene_;
  RenderSettings settings_;
  double exposure_ = 1.0;
  std::vector<Eigen::Vector3f> rays_;  // unit directions, camera frame, row-major
  cv::Mat background_;                 // CV_32FC3 RGB radiance of the lit room
  cv::Mat floor_;                      // CV_8U, 1 where the room's floor is seen
  std::shared_ptr<const SensorNoise> noise_;
};

}  // namespace silnet::sim
