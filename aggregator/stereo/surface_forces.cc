#include "aggregator/stereo/surface_forces.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>

#include "aggregator/hulls/silhouette_interpolation.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Bilinear sample of a CV_32FC1 map at (u, v) (pixel centres at integers) with its gradient;
// false outside the map's inner area.
bool SampleWithGradient(const cv::Mat& map, double u, double v, double* value,
                        Eigen::Vector2d* gradient) {
  if (!(u >= 0 && v >= 0 && u < map.cols - 1 && v < map.rows - 1)) return false;
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const double fx = u - x, fy = v - y;
  const float* r0 = map.ptr<float>(y) + x;
  const float* r1 = map.ptr<float>(y + 1) + x;
  *value = (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
  *gradient = Eigen::Vector2d((1 - fy) * (r0[1] - r0[0]) + fy * (r1[1] - r1[0]),
                              (1 - fx) * (r1[0] - r0[0]) + fx * (r1[1] - r0[1]));
  return true;
}

}  // namespace

std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[static_cast<size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[static_cast<size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[static_cast<size_t>(t[2])].cast<double>();
    const Eigen::Vector3d area_normal = (b - a).cross(c - a);  // twice the area
    for (int32_t id : t)
      normals[static_cast<size_t>(id)] += area_normal;
  }
  for (Eigen::Vector3d& n : normals) {
    const double norm = n.norm();
    n = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::Zero();
  }
  return normals;
}

std::vector<double> VertexCurvatures(const TriangleMesh& mesh, const VertexNeighbours& neighbours,
                                     const std::vector<Eigen::Vector3d>& normals, int rounds) {
  SILNET_CHECK(normals.size() == mesh.vertices.size());
  SILNET_CHECK(neighbours.begin.size() == mesh.vertices.size() + 1);
  std::vector<double> curvature(mesh.vertices.size(), 0.0);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    double sum = 0;
    size_t count = 0;
    for (size_t k = neighbours.begin[i]; k < neighbours.begin[i + 1]; ++k) {
      const Eigen::Vector3d d =
          (mesh.vertices[i] - mesh.vertices[static_cast<size_t>(neighbours.ids[k])]).cast<double>();
      const double squared = d.squaredNorm();
      if (squared <= 0) continue;
      sum += 2 * d.dot(normals[i]) / squared;
      ++count;
    }
    if (count > 0) curvature[i] = sum / static_cast<double>(count);
  }
  for (int round = 0; round < rounds; ++round) {
    std::vector<double> next(curvature.size());
    for (size_t i = 0; i < curvature.size(); ++i) {
      double sum = curvature[i];
      for (size_t k = neighbours.begin[i]; k < neighbours.begin[i + 1]; ++k)
        sum += curvature[static_cast<size_t>(neighbours.ids[k])];
      next[i] = sum / static_cast<double>(1 + neighbours.begin[i + 1] - neighbours.begin[i]);
    }
    curvature.swap(next);
  }
  return curvature;
}

std::vector<NormalOffset> TextureForces(const TriangleMesh& mesh,
                                        const std::vector<Eigen::Vector3d>& normals,
                                        const std::vector<double>& curvatures,
                                        const PatchScorer& scorer,
                                        const TextureForceOptions& options, int threads,
                                        const std::vector<uint8_t>& skip) {
  SILNET_CHECK(options.range > 0 && options.step > 0 && options.patch_step > 0);
  SILNET_CHECK(normals.size() == mesh.vertices.size());
  SILNET_CHECK(curvatures.size() == mesh.vertices.size());
  const double max_curvature = 1.0 / ((scorer.options().mu / 2) * options.patch_step);
  const int half = std::max(1, static_cast<int>(std::lround(options.range / options.step)));
  std::vector<double> shifts;
  for (int k = -half; k <= half; ++k)
    shifts.push_back(k * options.step);
  std::vector<NormalOffset> forces(mesh.vertices.size());
  ParallelFor(mesh.vertices.size(), threads, [&](size_t i) {
    const Eigen::Vector3d& n = normals[i];
    if (n.isZero() || (!skip.empty() && skip[i] != 0)) return;
    const Eigen::Vector3d x = mesh.vertices[i].cast<double>();
    const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
    const std::vector<float> scores =
        scorer.AlongNormal(x, n, u, v, options.patch_step,
                           std::clamp(curvatures[i], -max_curvature, max_curvature), shifts);
    const size_t best =
        static_cast<size_t>(std::max_element(scores.begin(), scores.end()) - scores.begin());
    if (scores[best] < options.min_score) return;
    double k = static_cast<double>(best) - half;
    if (best > 0 && best + 1 < scores.size()) {
      const double before = scores[best - 1], at = scores[best], after = scores[best + 1];
      const double curvature = before - 2 * at + after;
      if (curvature < 0) k += std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
    }
    forces[i] = {static_cast<float>(k * options.step), scores[best]};
  });
  return forces;
}

SilhouetteForce::SilhouetteForce(const std::vector<StereoView>& views,
                                 const SilhouetteForceOptions& options)
    : options_(options) {
  views_.reserve(views.size());
  for (const StereoView& view : views) {
    View v;
    v.projection = view.camera.ProjectionMatrix();
    v.centre = view.camera.Center();
    const int inside = cv::countNonZero(view.mask);
    if (inside > 0 && inside < static_cast<int>(view.mask.total()))
      v.signed_distance = SignedDistanceMap(view.mask);
    views_.push_back(std::move(v));
  }
}

NormalOffset SilhouetteForce::At(const Eigen::Vector3d& x, const Eigen::Vector3d& normal) const {
  double offset = std::numeric_limits<double>::infinity();
  for (const View& view : views_) {
    if (view.signed_distance.empty()) continue;
    const Eigen::Vector3d p = view.projection * x.homogeneous();
    if (p.z() <= 0) continue;
    const double u = p.x() / p.z(), v = p.y() / p.z();
    double distance = 0;
    Eigen::Vector2d gradient;
    if (!SampleWithGradient(view.signed_distance, u, v, &distance, &gradient)) continue;
    // Over a background pixel's centre (the outline is half a pixel outside the silhouette's)
    // any view pushes, back to that centre; inside, only a view whose rim the vertex is on
    // pulls it out to the outline.
    const double facing = std::abs(normal.dot((view.centre - x).normalized()));
    const bool rim = facing < options_.rim_cos;
    double target = 0;
    if (distance < -0.5) {
      target = -0.5;
    } else if (!(rim && distance <= options_.rim_distance_px)) {
      continue;
    }
    // d(pixel)/d(offset along the normal), then d(distance)/d(offset).
    const Eigen::Vector3d dp = view.projection.leftCols<3>() * normal;
    const Eigen::Vector2d pixel_rate((dp.x() - u * dp.z()) / p.z(), (dp.y() - v * dp.z()) / p.z());
    const double rate = gradient.dot(pixel_rate);
    // Moving along the normal must leave the silhouette across its outline.
    if (rate > -0.5 * pixel_rate.norm()) continue;
    offset = std::min(offset, (target - distance) / rate);
  }
  if (!std::isfinite(offset)) return {};
  return {static_cast<float>(offset), 1.0f};
}

std::vector<NormalOffset> SilhouetteForce::AtVertices(const TriangleMesh& mesh,
                                                      const std::vector<Eigen::Vector3d>& normals,
                                                      int threads) const {
  SILNET_CHECK(normals.size() == mesh.vertices.size());
  std::vector<NormalOffset> forces(mesh.vertices.size());
  ParallelFor(mesh.vertices.size(), threads, [&](size_t i) {
    if (!normals[i].isZero()) forces[i] = At(mesh.vertices[i].cast<double>(), normals[i]);
  });
  return forces;
}

}  // namespace silnet::aggregator
