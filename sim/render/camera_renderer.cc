#include "sim/render/camera_renderer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "shared/util/check.h"

namespace silnet::sim {
namespace {

constexpr float kNoHit = std::numeric_limits<float>::infinity();

PixelBox Intersect(const PixelBox& a, const PixelBox& b) {
  return {std::max(a.x0, b.x0), std::max(a.y0, b.y0), std::min(a.x1, b.x1), std::min(a.y1, b.y1)};
}

PixelBox Union(const PixelBox& a, const PixelBox& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

uint8_t ToByte(float value) {
  return static_cast<uint8_t>(std::clamp(value + 0.5f, 0.0f, 255.0f));
}

}  // namespace

CameraRenderer::CameraRenderer(const CameraModel& camera, const Scene& scene,
                               const RenderSettings& settings, int camera_index,
                               std::shared_ptr<const SensorNoise> noise)
    : camera_(camera), scene_(&scene), settings_(settings), noise_(std::move(noise)) {
  SILNET_CHECK(camera.width > 0 && camera.height > 0);
  std::mt19937_64 rng(MixSeed(settings.seed, static_cast<uint64_t>(camera_index), 0xCA3u));
  exposure_ = std::uniform_real_distribution<double>(0.9, 1.1)(rng);
  const size_t pixels = static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height);
  rays_.resize(pixels);
  background_.create(camera.height, camera.width, CV_32FC3);
  floor_.create(camera.height, camera.width, CV_8U);
  const Environment& environment = scene.environment();
  const Eigen::Vector3d center = camera.Center();
  const Eigen::Matrix3d world_from_cam = camera.R.transpose();
  for (int y = 0; y < camera.height; ++y) {
    auto* bg = background_.ptr<cv::Vec3f>(y);
    auto* fl = floor_.ptr<uint8_t>(y);
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.PixelRay({x, y}).normalized();
      rays_[static_cast<size_t>(y) * static_cast<size_t>(camera.width) + static_cast<size_t>(x)] =
          ray.cast<float>();
      const RoomHit hit = environment.Trace(center, world_from_cam * ray);
      const Eigen::Vector3d radiance = hit.albedo * environment.Shading(hit.normal);
      bg[x] = cv::Vec3f(static_cast<float>(radiance.x()), static_cast<float>(radiance.y()),
                        static_cast<float>(radiance.z()));
      fl[x] = hit.surface == RoomSurface::kFloor ? 1 : 0;
    }
  }
  const size_t values = pixels * 3;
  if (noise_ == nullptr || noise_->values_per_image() != values) {
    noise_ = std::make_shared<SensorNoise>(
        settings.noise_sigma, values,
        MixSeed(settings.seed, static_cast<uint64_t>(camera_index), 0x5E5u));
  }
}

PixelBox CameraRenderer::ProjectedBox(const Eigen::Vector3d& c, double r) const {
  const PixelBox image{0, 0, camera_.width, camera_.height};
  if (c.z() - r < 1e-3) return image;  // reaches behind the camera: no useful bound
  const double z_near = c.z() - r, z_far = c.z() + r;
  const double xs[4] = {(c.x() - r) / z_near, (c.x() - r) / z_far, (c.x() + r) / z_near,
                        (c.x() + r) / z_far};
  const double ys[4] = {(c.y() - r) / z_near, (c.y() - r) / z_far, (c.y() + r) / z_near,
                        (c.y() + r) / z_far};
  const double x_min = *std::min_element(xs, xs + 4), x_max = *std::max_element(xs, xs + 4);
  const double y_min = *std::min_element(ys, ys + 4), y_max = *std::max_element(ys, ys + 4);
  double u_min = std::numeric_limits<double>::infinity(), u_max = -u_min;
  double v_min = u_min, v_max = -u_min;
  constexpr int kSamples = 8;
  for (int i = 0; i <= kSamples; ++i) {
    const double f = static_cast<double>(i) / kSamples;
    const double x = x_min + f * (x_max - x_min), y = y_min + f * (y_max - y_min);
    for (const Eigen::Vector2d& n : {Eigen::Vector2d(x, y_min), Eigen::Vector2d(x, y_max),
                                     Eigen::Vector2d(x_min, y), Eigen::Vector2d(x_max, y)}) {
      const auto pixel = camera_.ProjectCameraPoint(n.homogeneous());
      u_min = std::min(u_min, pixel->x());
      u_max = std::max(u_max, pixel->x());
      v_min = std::min(v_min, pixel->y());
      v_max = std::max(v_max, pixel->y());
    }
  }
  const double margin = camera_.HasDistortion() ? 3.0 : 1.0;
  auto to_int = [](double v) { return static_cast<int>(std::clamp(v, -1e6, 1e6)); };
  const PixelBox box{to_int(std::floor(u_min - margin)), to_int(std::floor(v_min - margin)),
                     to_int(std::ceil(u_max + margin)) + 1, to_int(std::ceil(v_max + margin)) + 1};
  return Intersect(box, image);
}

void CameraRenderer::Render(double time, uint64_t image_seed, cv::Mat* mask,
                            cv::Mat* colour) const {
  RenderPrimitives(scene_->PrimitivesAt(time), scene_->environment().LightGain(time), image_seed,
                   mask, colour);
}

void CameraRenderer::RenderPrimitives(const std::vector<Primitive>& world, double light_gain,
                                      uint64_t image_seed, cv::Mat* mask, cv::Mat* colour) const {
  const int width = camera_.width, height = camera_.height;
  // Primitives in the camera frame and their pixel boxes.
  std::vector<Primitive> cam;
  std::vector<PixelBox> boxes;
  cam.reserve(world.size());
  PixelBox all;
  for (const Primitive& p : world) {
    cam.push_back(p.Transformed(camera_.R, camera_.t));
    const Primitive& q = cam.back();
    PixelBox box;
    if (q.BoundingCenter().z() + q.BoundingRadius() > 0.0) {
      box = ProjectedBox(q.BoundingCenter(), q.BoundingRadius());
    }
    boxes.push_back(box);
    all = Union(all, box);
  }
  // Depth test over each primitive's box: nearest hit along each pixel's ray. A mask alone
  // needs only whether a ray hits anything: pixels already hit are not tested again.
  const bool any_hit = colour == nullptr;
  const int box_width = std::max(0, all.x1 - all.x0);
  const int box_height = std::max(0, all.y1 - all.y0);
  std::vector<float> depth(static_cast<size_t>(box_width) * static_cast<size_t>(box_height),
                           kNoHit);
  std::vector<int16_t> owner(depth.size(), -1);
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < cam.size(); ++i) {
    const PixelBox& box = boxes[i];
    for (int y = box.y0; y < box.y1; ++y) {
      for (int x = box.x0; x < box.x1; ++x) {
        const size_t k = static_cast<size_t>(y - all.y0) * static_cast<size_t>(box_width) +
                         static_cast<size_t>(x - all.x0);
        if (any_hit && owner[k] >= 0) continue;
        double t = 0.0;
        if (!cam[i].Intersect(origin, Ray(x, y), &t)) continue;
        if (t < depth[k]) {
          depth[k] = static_cast<float>(t);
          owner[k] = static_cast<int16_t>(i);
        }
      }
    }
  }
  auto owner_at = [&](int x, int y) -> int {
    if (x < all.x0 || x >= all.x1 || y < all.y0 || y >= all.y1) return -1;
    return owner[static_cast<size_t>(y - all.y0) * static_cast<size_t>(box_width) +
                 static_cast<size_t>(x - all.x0)];
  };

  if (mask != nullptr) {
    mask->create(height, width, CV_8U);
    mask->setTo(0);
    for (int y = all.y0; y < all.y1; ++y) {
      auto* row = mask->ptr<uint8_t>(y);
      for (int x = all.x0; x < all.x1; ++x) {
        if (owner_at(x, y) >= 0) row[x] = 255;
      }
    }
  }
  if (colour == nullptr) return;

  // Cast shadows: floor pixels whose path to the light is blocked by a primitive. Each
  // primitive's shadow lies within a disc on the floor; only pixels seeing that disc are
  // tested against it.
  const Environment& environment = scene_->environment();
  const Eigen::Vector3d& light = environment.light_direction();
  cv::Mat shadow(height, width, CV_8U, cv::Scalar(0));
  if (settings_.shadows && light.z() > 0.05) {
    const Eigen::Vector3d center = camera_.Center();
    const Eigen::Matrix3d cam_to_world = camera_.R.transpose();
    for (const Primitive& p : world) {
      const Eigen::Vector3d c = p.BoundingCenter();
      const Eigen::Vector3d disc = c - (c.z() / light.z()) * light;
      const PixelBox box =
          ProjectedBox(camera_.R * disc + camera_.t, p.BoundingRadius() / light.z());
      for (int y = box.y0; y < box.y1; ++y) {
        const auto* fl = floor_.ptr<uint8_t>(y);
        auto* sh = shadow.ptr<uint8_t>(y);
        for (int x = box.x0; x < box.x1; ++x) {
          if (fl[x] == 0 || sh[x] != 0 || owner_at(x, y) >= 0) continue;
          const Eigen::Vector3d dir = cam_to_world * Ray(x, y);
          if (dir.z() >= 0.0) continue;
          const Eigen::Vector3d point = center - (center.z() / dir.z()) * dir;
          double t = 0.0;
          if (p.Intersect(point, light, &t)) sh[x] = 1;
        }
      }
    }
  }

  // The room: precomputed radiance, darkened in shadows, scaled by light and exposure.
  const float floor_shadow =
      static_cast<float>(environment.ambient() / environment.Shading(Eigen::Vector3d::UnitZ()));
  const double scale = 255.0 * exposure_ * light_gain;
  const int8_t* noise = noise_->ForImage(image_seed);
  colour->create(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    const auto* bg = background_.ptr<cv::Vec3f>(y);
    const auto* sh = shadow.ptr<uint8_t>(y);
    auto* out = colour->ptr<uint8_t>(y);
    const int8_t* row_noise = noise + static_cast<size_t>(y) * static_cast<size_t>(width) * 3;
    for (int x = 0; x < width; ++x) {
      const float factor = static_cast<float>(scale) * (sh[x] != 0 ? floor_shadow : 1.0f);
      out[3 * x + 0] = ToByte(bg[x][2] * factor + static_cast<float>(row_noise[3 * x + 0]));
      out[3 * x + 1] = ToByte(bg[x][1] * factor + static_cast<float>(row_noise[3 * x + 1]));
      out[3 * x + 2] = ToByte(bg[x][0] * factor + static_cast<float>(row_noise[3 * x + 2]));
    }
  }

  // The subjects: Lambertian shading of solid textures.
  const Eigen::Matrix3d world_from_cam = camera_.R.transpose();
  const std::vector<Material>& materials = scene_->materials();
  for (int y = all.y0; y < all.y1; ++y) {
    auto* out = colour->ptr<uint8_t>(y);
    const int8_t* row_noise = noise + static_cast<size_t>(y) * static_cast<size_t>(width) * 3;
    for (int x = all.x0; x < all.x1; ++x) {
      const size_t k = static_cast<size_t>(y - all.y0) * static_cast<size_t>(box_width) +
                       static_cast<size_t>(x - all.x0);
      if (owner[k] < 0) continue;
      const Primitive& p = cam[static_cast<size_t>(owner[k])];
      const Eigen::Vector3d point = static_cast<double>(depth[k]) * Ray(x, y);
      const double shade = environment.Shading(world_from_cam * p.Normal(point));
      const Eigen::Vector3d rgb =
          materials[static_cast<size_t>(p.material)].ColorAt(p.LocalPoint(point)) * (shade * scale);
      out[3 * x + 0] =
          ToByte(static_cast<float>(rgb.z()) + static_cast<float>(row_noise[3 * x + 0]));
      out[3 * x + 1] =
          ToByte(static_cast<float>(rgb.y()) + static_cast<float>(row_noise[3 * x + 1]));
      out[3 * x + 2] =
          ToByte(static_cast<float>(rgb.x()) + static_cast<float>(row_noise[3 * x + 2]));
    }
  }
}

}  // namespace silnet::sim
