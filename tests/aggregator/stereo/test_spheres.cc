#include "tests/aggregator/stereo/test_spheres.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>

#include "aggregator/stereo/triangle_remeshing.h"

namespace silnet::aggregator::testing {

TriangleMesh Icosphere(const Eigen::Vector3d& centre, double radius, int levels) {
  const float p = (1.0f + std::sqrt(5.0f)) / 2.0f;
  TriangleMesh mesh;
  mesh.vertices = {{-1, p, 0},  {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p},  {0, 1, p},
                   {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Eigen::Vector3f& x : mesh.vertices)
    x.normalize();
  for (int level = 0; level < levels; ++level) {
    SubdivideLongEdges(
        &mesh, [](int32_t, int32_t) { return true; }, SIZE_MAX);
    for (Eigen::Vector3f& x : mesh.vertices)
      x.normalize();
  }
  for (Eigen::Vector3f& x : mesh.vertices)
    x = (centre + radius * x.cast<double>()).cast<float>();
  return mesh;
}

void AppendPiece(const TriangleMesh& piece, TriangleMesh* mesh) {
  const auto offset = static_cast<int32_t>(mesh->vertices.size());
  mesh->vertices.insert(mesh->vertices.end(), piece.vertices.begin(), piece.vertices.end());
  for (auto t : piece.triangles) {
    for (int32_t& v : t)
      v += offset;
    mesh->triangles.push_back(t);
  }
}

std::vector<StereoView> TexturedSphereViews(const Eigen::Vector3d& centre, double radius,
                                            int cameras, double distance, int width, int height,
                                            double focal) {
  std::vector<StereoView> views;
  for (int c = 0; c < cameras; ++c) {
    const double angle = 2 * std::numbers::pi * c / cameras;
    const Eigen::Vector3d eye =
        centre + distance * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    StereoView view;
    CameraModel& camera = view.camera;
    camera.id = "cam" + std::to_string(c);
    camera.width = width;
    camera.height = height;
    camera.K << focal, 0, (width - 1) / 2.0, 0, focal, (height - 1) / 2.0, 0, 0, 1;
    camera.R = LookAtRotation(eye, centre, Eigen::Vector3d::UnitZ());
    camera.t = -camera.R * eye;
    view.image = cv::Mat(height, width, CV_8UC3, cv::Scalar(20, 20, 20));
    view.mask = cv::Mat::zeros(height, width, CV_8UC1);
    const Eigen::Matrix3d to_world = camera.R.transpose() * camera.K.inverse();
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector3d ray = (to_world * Eigen::Vector3d(x, y, 1)).normalized();
        const Eigen::Vector3d to_centre = centre - eye;
        const double along = to_centre.dot(ray);
        const double miss_squared = to_centre.squaredNorm() - along * along;
        if (miss_squared >= radius * radius) continue;
        const Eigen::Vector3d hit = eye + (along - std::sqrt(radius * radius - miss_squared)) * ray;
        const Eigen::Vector3d q = hit - centre;
        const double texture = std::sin(310 * q.x() + 0.3) * std::sin(270 * q.y() + 1.1) +
                               0.6 * std::sin(230 * q.z() + 370 * q.x()) +
                               0.4 * std::sin(420 * q.y() - 190 * q.z());
        const auto grey = cv::saturate_cast<uint8_t>(128 + 50 * texture);
        view.image.at<cv::Vec3b>(y, x) = cv::Vec3b(grey, grey, grey);
        view.mask.at<uint8_t>(y, x) = 255;
      }
    }
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace silnet::aggregator::testing
