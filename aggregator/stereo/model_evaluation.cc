#include "aggregator/stereo/model_evaluation.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/nearest_point.h"
#include "aggregator/stereo/traded_outer_pixels.h"
#include "aggregator/stereo/uncoverable_pixels.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// True points whose nearest-neighbour distances estimate the truth's spacing.
constexpr size_t kSpacingProbes = 20000;

Eigen::Vector3d Vertex(const TriangleMesh& mesh, int32_t index) {
  return mesh.vertices[static_cast<size_t>(index)].cast<double>();
}

// For a uniformly random sample of density 1/s^2 the median nearest-neighbour distance is
// sqrt(ln 2 / pi) s = 0.47 s: s is about twice it.
double EstimateSpacing(const std::vector<Eigen::Vector3d>& points, const NearestPoint& tree) {
  if (points.size() < 2) return 0.0;
  const size_t step = std::max<size_t>(1, points.size() / kSpacingProbes);
  std::vector<Eigen::Vector3d> probes;
  for (size_t i = 0; i < points.size(); i += step)
    probes.push_back(points[i]);
  std::vector<int> indices;
  std::vector<double> distances;
  tree.KNearest(probes, 2, &indices, &distances);
  std::vector<double> nearest;
  for (size_t i = 0; i < probes.size(); ++i)
    nearest.push_back(distances[2 * i + 1]);
  std::nth_element(nearest.begin(), nearest.begin() + static_cast<long>(nearest.size() / 2),
                   nearest.end());
  return 2.0 * nearest[nearest.size() / 2];
}

// Distance from each query to the surface sampled by (points, normals) at `spacing`: the
// smallest over the `k` nearest samples of sqrt((n.d)^2 + max(0, |d_tangential| - spacing)^2).
// With `nearest`, also each query's nearest sample (-1 for none).
std::vector<double> SurfaceDistances(const std::vector<Eigen::Vector3d>& queries,
                                     const std::vector<Eigen::Vector3d>& points,
                                     const std::vector<Eigen::Vector3d>& normals,
                                     const NearestPoint& tree, double spacing, int k,
                                     std::vector<int>* nearest = nullptr) {
  std::vector<int> indices;
  std::vector<double> unused;
  tree.KNearest(queries, k, &indices, &unused);
  std::vector<double> out(queries.size(), std::numeric_limits<double>::infinity());
  const size_t kk = static_cast<size_t>(k);
  if (nearest != nullptr) {
    nearest->resize(queries.size());
    for (size_t q = 0; q < queries.size(); ++q)
      (*nearest)[q] = indices[q * kk];
  }
  for (size_t q = 0; q < queries.size(); ++q) {
    for (size_t j = 0; j < kk; ++j) {
      const int i = indices[q * kk + j];
      if (i < 0) continue;
      const Eigen::Vector3d d = queries[q] - points[static_cast<size_t>(i)];
      const Eigen::Vector3d& n = normals[static_cast<size_t>(i)];
      const double along = n.dot(d);
      const double across = std::max(0.0, (d - along * n).norm() - spacing);
      out[q] = std::min(out[q], std::sqrt(along * along + across * across));
    }
  }
  return out;
}

// The value below which `fraction` of `values` lie (nearest rank).
double Quantile(std::vector<double> values, double fraction) {
  if (values.empty()) return std::numeric_limits<double>::infinity();
  const size_t rank =
      std::min(values.size() - 1,
               static_cast<size_t>(std::ceil(fraction * static_cast<double>(values.size()))) - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<long>(rank), values.end());
  return values[rank];
}

// The share of `distances` at most `within`, 0 for none.
double FractionWithin(const std::vector<double>& distances, double within) {
  if (distances.empty()) return 0.0;
  const auto count =
      std::count_if(distances.begin(), distances.end(), [within](double d) { return d <= within; });
  return static_cast<double>(count) / static_cast<double>(distances.size());
}

}  // namespace

bool ModelEvaluationOptions::IsValid(std::string* reason) const {
  if (!(footprint > 0)) {
    *reason = "the footprint must be positive";
    return false;
  }
  if (!(sample_spacing_footprints > 0)) {
    *reason = "the model sampling spacing must be positive";
    return false;
  }
  if (threads < 0) {
    *reason = "threads must be >= 0";
    return false;
  }
  if (!(accuracy_fraction > 0 && accuracy_fraction <= 1)) {
    *reason = "the accuracy fraction must be in (0, 1]";
    return false;
  }
  for (double d : completeness_footprints) {
    if (!(d > 0)) {
      *reason = "completeness distances must be positive";
      return false;
    }
  }
  if (!(truth_spacing >= 0)) {
    *reason = "the truth spacing must be >= 0 (0 = estimated)";
    return false;
  }
  if (neighbours < 1 || max_samples < 1) {
    *reason = "neighbours and max_samples must be at least 1";
    return false;
  }
  return true;
}

std::string RegionEvaluation::Brief() const {
  std::string text = fmt::format("{} true points: accuracy {:.2f} mm ({:.2f} fp), completeness",
                                 truth_points, accuracy_m * 1e3, accuracy_footprints);
  for (const Completeness& c : completeness)
    text += fmt::format(" {:.1f} % within {:g} fp", 100 * c.fraction, c.distance_footprints);
  return text;
}

RegionEvaluation EvaluateRegion(const SurfaceRegion& region, const ModelDistances& distances,
                                const ModelEvaluationOptions& options) {
  SILNET_CHECK_MSG(region.truth.size() == distances.truth_to_model.size(), region.name);
  RegionEvaluation result;
  result.name = region.name;
  std::vector<double> samples, truths;
  for (size_t s = 0; s < distances.nearest_truth.size(); ++s) {
    const int t = distances.nearest_truth[s];
    if (t >= 0 && region.truth[static_cast<size_t>(t)] != 0)
      samples.push_back(distances.sample_to_truth[s]);
  }
  for (size_t t = 0; t < region.truth.size(); ++t) {
    if (region.truth[t] != 0) truths.push_back(distances.truth_to_model[t]);
  }
  result.truth_points = truths.size();
  result.model_samples = samples.size();
  result.accuracy_m = Quantile(samples, options.accuracy_fraction);
  result.accuracy_footprints = result.accuracy_m / options.footprint;
  for (double d : options.completeness_footprints)
    result.completeness.push_back(
        {d * options.footprint, d, FractionWithin(truths, d * options.footprint)});
  return result;
}

const RegionEvaluation* ModelEvaluation::Region(const std::string& name) const {
  for (const RegionEvaluation& region : regions) {
    if (region.name == name) return &region;
  }
  return nullptr;
}

std::string ModelEvaluation::Brief() const {
  std::string text = fmt::format("accuracy {:.2f} mm ({:.2f} fp), completeness", accuracy_m * 1e3,
                                 accuracy_footprints);
  for (const Completeness& c : completeness)
    text += fmt::format(" {:.1f} % within {:g} fp", 100 * c.fraction, c.distance_footprints);
  return text;
}

SurfaceSample SampleSurfaceBySpacing(const TriangleMesh& mesh, double spacing, uint64_t seed) {
  SILNET_CHECK(spacing > 0);
  std::vector<double> cumulative;
  cumulative.reserve(mesh.triangles.size());
  double total = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = Vertex(mesh, t[0]);
    total += 0.5 * (Vertex(mesh, t[1]) - a).cross(Vertex(mesh, t[2]) - a).norm();
    cumulative.push_back(total);
  }
  SurfaceSample sample;
  if (!(total > 0)) return sample;
  const size_t count =
      std::max<size_t>(1, static_cast<size_t>(std::llround(total / (spacing * spacing))));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  sample.points.reserve(count);
  sample.normals.reserve(count);
  for (size_t s = 0; s < count; ++s) {
    const size_t t =
        std::min(mesh.triangles.size() - 1,
                 static_cast<size_t>(
                     std::lower_bound(cumulative.begin(), cumulative.end(), uniform(rng) * total) -
                     cumulative.begin()));
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d a = Vertex(mesh, tri[0]), ab = Vertex(mesh, tri[1]) - a,
                          ac = Vertex(mesh, tri[2]) - a;
    double u = uniform(rng), v = uniform(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    sample.points.push_back(a + u * ab + v * ac);
    const Eigen::Vector3d n = ab.cross(ac);
    sample.normals.push_back(n.norm() > 0 ? Eigen::Vector3d(n.normalized())
                                          : Eigen::Vector3d::Zero());
  }
  return sample;
}

TruthSurface::TruthSurface(const std::vector<Eigen::Vector3d>& points,
                           const std::vector<Eigen::Vector3d>& normals, double spacing, int threads)
    : points_(points), normals_(normals) {
  SILNET_CHECK(points.size() == normals.size());
  index_ = std::make_unique<NearestPoint>(points, threads);
  spacing_ = spacing > 0 ? spacing : EstimateSpacing(points, *index_);
}

TruthSurface::~TruthSurface() = default;

ModelEvaluation EvaluateModel(const TriangleMesh& model,
                              const std::vector<Eigen::Vector3d>& truth_points,
                              const std::vector<Eigen::Vector3d>& truth_normals,
                              const ModelEvaluationOptions& options,
                              const std::vector<SurfaceRegion>& regions,
                              ModelDistances* distances) {
  std::string why;
  SILNET_CHECK_MSG(options.IsValid(&why), why);
  const TruthSurface truth(truth_points, truth_normals, options.truth_spacing, options.threads);
  return EvaluateModel(model, truth, options, regions, distances);
}

ModelEvaluation EvaluateModel(const TriangleMesh& model, const TruthSurface& truth,
                              const ModelEvaluationOptions& options,
                              const std::vector<SurfaceRegion>& regions,
                              ModelDistances* distances) {
  std::string why;
  SILNET_CHECK_MSG(options.IsValid(&why), why);
  const std::vector<Eigen::Vector3d>& truth_points = truth.points();
  for (const SurfaceRegion& region : regions)
    SILNET_CHECK_MSG(region.truth.size() == truth_points.size(), region.name);
  ModelEvaluation result;
  result.footprint = options.footprint;
  result.truth_points = truth_points.size();
  result.accuracy_m = result.accuracy_footprints = result.mean_distance_m =
      std::numeric_limits<double>::infinity();
  for (double d : options.completeness_footprints)
    result.completeness.push_back({d * options.footprint, d, 0.0});

  double area = 0;
  for (const auto& t : model.triangles) {
    const Eigen::Vector3d a = Vertex(model, t[0]);
    area += 0.5 * (Vertex(model, t[1]) - a).cross(Vertex(model, t[2]) - a).norm();
  }
  result.sample_spacing = std::max(options.sample_spacing_footprints * options.footprint,
                                   std::sqrt(area / static_cast<double>(options.max_samples)));
  const SurfaceSample sample =
      SampleSurfaceBySpacing(model, result.sample_spacing, options.random_seed);
  result.model_samples = sample.points.size();
  ModelDistances measured;
  measured.truth_to_model.assign(truth_points.size(), std::numeric_limits<double>::infinity());
  const auto finish = [&]() {
    for (const SurfaceRegion& region : regions)
      result.regions.push_back(EvaluateRegion(region, measured, options));
    if (distances != nullptr) *distances = std::move(measured);
    return result;
  };
  if (sample.points.empty() || truth_points.empty()) return finish();

  result.truth_spacing = truth.spacing();
  measured.sample_to_truth =
      SurfaceDistances(sample.points, truth_points, truth.normals(), truth.index(),
                       result.truth_spacing, options.neighbours, &measured.nearest_truth);
  const std::vector<double>& to_truth = measured.sample_to_truth;
  result.accuracy_m = Quantile(to_truth, options.accuracy_fraction);
  result.accuracy_footprints = result.accuracy_m / options.footprint;
  double sum = 0;
  for (double d : to_truth)
    sum += d;
  result.mean_distance_m = sum / static_cast<double>(to_truth.size());

  const NearestPoint model_tree(sample.points, options.threads);
  measured.truth_to_model = SurfaceDistances(truth_points, sample.points, sample.normals,
                                             model_tree, result.sample_spacing, options.neighbours);
  for (Completeness& c : result.completeness)
    c.fraction = FractionWithin(measured.truth_to_model, c.distance_m);
  return finish();
}

cv::Mat InnerSilhouettePixels(const cv::Mat& mask, double margin_px) {
  SILNET_CHECK(mask.type() == CV_8UC1);
  cv::Mat depth_in;
  cv::distanceTransform(mask != 0, depth_in, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  return depth_in >= margin_px + 0.5;
}

namespace {

// CompareSilhouetteConsistency with the mask's inner pixels (InnerSilhouettePixels at
// `margin_px`) already computed.
SilhouetteConsistency CompareWithInnerPixels(const cv::Mat& rendered, const cv::Mat& mask,
                                             const cv::Mat& inner, double margin_px,
                                             cv::Mat* missed_inner, cv::Mat* covered_outer) {
  SILNET_CHECK(rendered.type() == CV_8UC1 && mask.type() == CV_8UC1);
  SILNET_CHECK(rendered.size() == mask.size() && inner.size() == mask.size());
  if (missed_inner) *missed_inner = inner & (rendered == 0);
  cv::Mat depth_out;
  cv::distanceTransform(mask == 0, depth_out, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  const float threshold = static_cast<float>(margin_px + 0.5);
  if (covered_outer) *covered_outer = (depth_out >= threshold) & (rendered != 0);
  SilhouetteConsistency result;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    const uint8_t* r = rendered.ptr<uint8_t>(y);
    const uint8_t* in = inner.ptr<uint8_t>(y);
    const float* dout = depth_out.ptr<float>(y);
    for (int x = 0; x < mask.cols; ++x) {
      const bool covered = r[x] != 0;
      if (m[x] != 0) {
        ++result.silhouette_pixels;
        if (!covered) ++result.missed_pixels;
        if (in[x] != 0) {
          ++result.inner_pixels;
          if (!covered) ++result.missed_inner;
        }
      } else {
        if (covered) ++result.covered_background;
        if (dout[x] >= threshold) {
          ++result.outer_pixels;
          if (covered) ++result.covered_outer;
        }
      }
    }
  }
  return result;
}

}  // namespace

SilhouetteConsistency CompareSilhouetteConsistency(const cv::Mat& rendered, const cv::Mat& mask,
                                                   double margin_px, cv::Mat* missed_inner,
                                                   cv::Mat* covered_outer) {
  SILNET_CHECK(mask.type() == CV_8UC1);
  return CompareWithInnerPixels(rendered, mask, InnerSilhouettePixels(mask, margin_px), margin_px,
                                missed_inner, covered_outer);
}

double MissedInnerShare(const TriangleMesh& surface, const std::vector<CameraModel>& cameras,
                        const std::vector<cv::Mat>& masks, double margin_px) {
  SILNET_CHECK(cameras.size() == masks.size());
  size_t inner_pixels = 0, missed = 0;
  for (size_t v = 0; v < cameras.size(); ++v) {
    const cv::Mat inner = InnerSilhouettePixels(masks[v], margin_px);
    const cv::Mat covered = RenderMeshSilhouette(surface, cameras[v]);
    inner_pixels += static_cast<size_t>(cv::countNonZero(inner));
    missed += static_cast<size_t>(cv::countNonZero(inner & (covered == 0)));
  }
  return inner_pixels == 0 ? 0.0 : static_cast<double>(missed) / static_cast<double>(inner_pixels);
}

std::vector<SilhouetteConsistency> MeasureSilhouetteConsistency(
    const TriangleMesh& model, const std::vector<StereoView>& views, double margin_px,
    int threads) {
  std::vector<SilhouetteConsistency> out(views.size());
  const GrownSilhouettes grown = GrowSilhouettes(views, margin_px);
  std::vector<cv::Mat> inner(views.size()), covered_outer(views.size());
  std::vector<VertexPixels> projected(views.size());
  // Each view on its own (render, compare, its uncoverable misses); the outer pixels covered
  // in trade, rare, after them on one thread: they share a cache of other views' pixels.
  ParallelFor(views.size(), threads, [&](size_t v) {
    const StereoView& view = views[v];
    inner[v] = InnerSilhouettePixels(view.mask, margin_px);
    projected[v] = ProjectVertices(model, view.camera);
    const cv::Mat rendered =
        RenderMeshSilhouette(model, projected[v], view.camera.width, view.camera.height);
    cv::Mat missed;
    out[v] = CompareWithInnerPixels(rendered, view.mask, inner[v], margin_px, &missed,
                                    &covered_outer[v]);
    out[v].camera_id = view.camera.id;
    if (out[v].missed_inner > 0)
      out[v].missed_uncoverable = CountUncoverable(views, grown, v, missed);
  });
  std::optional<UncoverableInnerPixels> uncoverable;
  for (size_t v = 0; v < views.size(); ++v) {
    if (out[v].covered_outer == 0) continue;
    if (!uncoverable) uncoverable.emplace(views, grown, inner);
    out[v].covered_outer_traded = CountOuterCoveredForUncoverable(model, projected[v], views, v,
                                                                  covered_outer[v], *uncoverable);
  }
  return out;
}

}  // namespace silnet::aggregator
