#include "aggregator/stereo/patch_photo_consistency.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// A point's projection into one view, linearised for the patch around it.
struct Projected {
  bool usable = false;  // in front, inside the image and the silhouette
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> jacobian = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, from the point to the camera
};

// Bilinear sample of a CV_32FC1 image at (u, v), pixel centres at integers; the caller keeps
// (u, v) within [0, cols - 1] x [0, rows - 1].
float Bilinear(const cv::Mat& image, double u, double v) {
  const int x = std::min(static_cast<int>(u), image.cols - 2);
  const int y = std::min(static_cast<int>(v), image.rows - 2);
  const auto fx = static_cast<float>(u - x), fy = static_cast<float>(v - y);
  const float* row0 = image.ptr<float>(y) + x;
  const float* row1 = image.ptr<float>(y + 1) + x;
  return (1 - fy) * ((1 - fx) * row0[0] + fx * row0[1]) + fy * ((1 - fx) * row1[0] + fx * row1[1]);
}

}  // namespace

bool PatchOptions::IsValid(std::string* reason) const {
  const auto fail = [&](const char* why) {
    if (reason) *reason = why;
    return false;
  };
  if (mu < 3 || mu % 2 == 0) return fail("mu must be odd and at least 3");
  if (cameras < 2) return fail("cameras must be at least 2");
  if (min_views < 2 || min_views > cameras) return fail("min_views must be in [2, cameras]");
  if (!(max_angle_deg > 0 && max_angle_deg <= 90)) return fail("max_angle_deg must be in (0, 90]");
  if (!(min_std >= 0)) return fail("min_std must not be negative");
  return true;
}

const std::array<Eigen::Vector3d, 14>& CanonicalOrientations() {
  static const std::array<Eigen::Vector3d, 14> orientations = [] {
    std::array<Eigen::Vector3d, 14> o;
    int k = 0;
    for (int axis = 0; axis < 3; ++axis) {
      for (double sign : {1.0, -1.0}) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d[axis] = sign;
        o[k++] = d;
      }
    }
    for (double x : {1.0, -1.0})
      for (double y : {1.0, -1.0})
        for (double z : {1.0, -1.0})
          o[k++] = Eigen::Vector3d(x, y, z).normalized();
    return o;
  }();
  return orientations;
}

PatchScorer::PatchScorer(const std::vector<StereoView>& views, const PatchOptions& options)
    : options_(options) {
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  views_.reserve(views.size());
  for (const StereoView& view : views) {
    View v;
    v.projection = view.camera.ProjectionMatrix();
    v.centre = view.camera.Center();
    cv::Mat grey;
    if (view.image.channels() == 3)
      cv::cvtColor(view.image, grey, cv::COLOR_BGR2GRAY);
    else
      grey = view.image;
    grey.convertTo(v.grey, CV_32F);
    v.mask = &view.mask;
    v.width = view.image.cols;
    v.height = view.image.rows;
    SILNET_CHECK(v.width >= 2 && v.height >= 2);
    views_.push_back(std::move(v));
  }
}

bool PatchScorer::InsideSilhouettes(const Eigen::Vector3d& x) const {
  for (const View& view : views_) {
    const Eigen::Vector3d h = view.projection * x.homogeneous();
    if (h.z() <= 0) continue;
    const double u = h.x() / h.z(), v = h.y() / h.z();
    const int px = static_cast<int>(std::lround(u)), py = static_cast<int>(std::lround(v));
    if (px < 0 || py < 0 || px >= view.width || py >= view.height) continue;
    if (view.mask->at<uint8_t>(py, px) == 0) return false;
  }
  return true;
}

namespace {

// Per-thread scratch of the scorer.
struct Scratch {
  std::vector<Projected> projected;
  std::vector<int> chosen;
  std::vector<std::pair<double, int>> ranked;
  std::vector<Eigen::Vector3d> offsets;
  std::vector<Eigen::Vector3d> grid;  // AlongNormal: the flat patch it shifts and bends
  std::vector<float> values;          // views x points, normalised
  std::vector<float> correlation;     // views x views
  std::vector<float> row;
};

Scratch& ThreadScratch() {
  thread_local Scratch scratch;
  return scratch;
}

}  // namespace

void PatchScorer::ChooseViews(const Eigen::Vector3d& normal, std::vector<int>* chosen) const {
  Scratch& s = ThreadScratch();
  const double min_cos = std::cos(options_.max_angle_deg * std::numbers::pi / 180);
  s.ranked.clear();
  for (size_t v = 0; v < views_.size(); ++v) {
    const Projected& p = s.projected[v];
    if (!p.usable) continue;
    const double c = p.direction.dot(normal);
    if (c >= min_cos) s.ranked.emplace_back(-c, static_cast<int>(v));
  }
  const size_t keep = std::min(s.ranked.size(), static_cast<size_t>(options_.cameras));
  std::partial_sort(s.ranked.begin(), s.ranked.begin() + static_cast<std::ptrdiff_t>(keep),
                    s.ranked.end());
  chosen->clear();
  for (size_t i = 0; i < keep; ++i)
    chosen->push_back(s.ranked[i].second);
}

// Either offsets[i] (metres, any shape) or, without offsets, the plane grid x u + y v for x,
// y in -half, -half + stride, ... up to half (u and v in metres, a step apart), row by row.
struct PatchScorer::PatchPoints {
  const std::vector<Eigen::Vector3d>* offsets = nullptr;
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
  int half = 0, stride = 1;

  size_t size() const {
    if (offsets) return offsets->size();
    const auto side = static_cast<size_t>(2 * half / stride + 1);
    return side * side;
  }
};

PatchScore PatchScorer::Score(const PatchPoints& points, const std::vector<int>& chosen) const {
  Scratch& s = ThreadScratch();
  const size_t n = points.size();
  s.values.resize(chosen.size() * n);
  int good = 0;
  uint64_t mask = 0;
  for (int view : chosen) {
    const Projected& p = s.projected[view];
    const View& image = views_[view];
    const auto in_image = [&](const Eigen::Vector2d& q) {
      return q.x() >= 0 && q.y() >= 0 && q.x() <= image.width - 1 && q.y() <= image.height - 1;
    };
    float* out = s.values.data() + good * n;
    double sum = 0;
    if (points.offsets) {
      size_t i = 0;
      for (; i < n; ++i) {
        const Eigen::Vector2d q = p.pixel + p.jacobian * (*points.offsets)[i];
        if (!in_image(q)) break;
        out[i] = Bilinear(image.grey, q.x(), q.y());
        sum += out[i];
      }
      if (i < n) continue;  // a point outside the image
    } else {
      // The grid's image is affine: inside the image iff its four corners are.
      const Eigen::Vector2d a = p.jacobian * points.u, b = p.jacobian * points.v;
      const int first = -points.half;
      const int last = first + (2 * points.half / points.stride) * points.stride;
      if (!in_image(p.pixel + first * a + first * b) || !in_image(p.pixel + last * a + first * b) ||
          !in_image(p.pixel + first * a + last * b) || !in_image(p.pixel + last * a + last * b))
        continue;
      size_t i = 0;
      for (int y = first; y <= last; y += points.stride) {
        const Eigen::Vector2d row = p.pixel + y * b;
        for (int x = first; x <= last; x += points.stride, ++i) {
          const Eigen::Vector2d q = row + x * a;
          out[i] = Bilinear(image.grey, q.x(), q.y());
          sum += out[i];
        }
      }
    }
    const auto mean = static_cast<float>(sum / n);
    double squares = 0;
    for (size_t i = 0; i < n; ++i) {
      out[i] -= mean;
      squares += out[i] * out[i];
    }
    if (std::sqrt(squares / n) < options_.min_std) continue;
    const auto scale = static_cast<float>(1.0 / std::sqrt(squares));
    for (size_t i = 0; i < n; ++i)
      out[i] *= scale;
    if (view < 64) mask |= uint64_t{1} << view;
    ++good;
  }
  PatchScore result;
  result.views = good;
  result.view_mask = mask;
  if (good < options_.min_views) return result;
  s.correlation.assign(static_cast<size_t>(good * good), 0.0f);
  for (int a = 0; a < good; ++a) {
    for (int b = a + 1; b < good; ++b) {
      float dot = 0;
      const float* va = s.values.data() + a * n;
      const float* vb = s.values.data() + b * n;
      for (size_t i = 0; i < n; ++i)
        dot += va[i] * vb[i];
      s.correlation[a * good + b] = s.correlation[b * good + a] = dot;
    }
  }
  const int keep = std::min(good - 1, std::max(options_.cameras / 2, 3));
  for (int a = 0; a < good; ++a) {
    s.row.clear();
    for (int b = 0; b < good; ++b)
      if (b != a) s.row.push_back(s.correlation[a * good + b]);
    std::partial_sort(s.row.begin(), s.row.begin() + keep, s.row.end(), std::greater<>());
    float mean = 0;
    for (int i = 0; i < keep; ++i)
      mean += s.row[i];
    result.score = std::max(result.score, mean / keep);
  }
  return result;
}

namespace {

// Projects x into every view, linearised (see Projected).
template <typename ViewList>
void ProjectAll(const ViewList& views, const Eigen::Vector3d& x, std::vector<Projected>* out) {
  out->resize(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    Projected& p = (*out)[v];
    p.usable = false;
    const auto& view = views[v];
    const Eigen::Vector3d h = view.projection * x.homogeneous();
    if (h.z() <= 0) continue;
    p.pixel = h.head<2>() / h.z();
    const int px = static_cast<int>(std::lround(p.pixel.x()));
    const int py = static_cast<int>(std::lround(p.pixel.y()));
    if (px < 0 || py < 0 || px >= view.width || py >= view.height) continue;
    if (view.mask->template at<uint8_t>(py, px) == 0) continue;
    p.jacobian = (view.projection.template block<2, 3>(0, 0) -
                  p.pixel * view.projection.template block<1, 3>(2, 0)) /
                 h.z();
    p.direction = (view.centre - x).normalized();
    p.usable = true;
  }
}

// The points of a plane patch, every `stride`-th of (2 half + 1)^2 spaced `step` on u and v,
// row by row, into `out` (replaced).
void PatchGrid(int half, int stride, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
               double step, std::vector<Eigen::Vector3d>* out) {
  out->clear();
  for (int j = -half; j <= half; j += stride)
    for (int i = -half; i <= half; i += stride)
      out->push_back(step * (i * u + j * v));
}

}  // namespace

PatchScore PatchScorer::BestPlane(const Eigen::Vector3d& x, double step, double prefilter,
                                  int* orientation, int full_orientations) const {
  Scratch& s = ThreadScratch();
  ProjectAll(views_, x, &s.projected);
  PatchScore best;
  const auto& orientations = CanonicalOrientations();
  // Every other point first (most orientations end there); then, in full, the orientations
  // that passed, best first, at most full_orientations of them.
  std::array<std::pair<float, int>, 14> passed;
  size_t count = 0;
  for (size_t o = 0; o < orientations.size(); ++o) {
    ChooseViews(orientations[o], &s.chosen);
    if (static_cast<int>(s.chosen.size()) < options_.min_views) continue;
    float coarse = 1.0f;
    if (prefilter > -1) {
      const Eigen::Vector3d u = orientations[o].unitOrthogonal();
      coarse = ScoreSpanned(u, orientations[o].cross(u), step, 2).score;
      if (coarse < prefilter) continue;
    }
    passed[count++] = {-coarse, static_cast<int>(o)};
  }
  std::sort(passed.begin(), passed.begin() + static_cast<std::ptrdiff_t>(count));
  const size_t limit = prefilter > -1 ? static_cast<size_t>(std::max(1, full_orientations)) : count;
  for (size_t k = 0; k < std::min(count, limit); ++k) {
    const int o = passed[k].second;
    ChooseViews(orientations[o], &s.chosen);
    const Eigen::Vector3d u = orientations[o].unitOrthogonal();
    const PatchScore score = ScoreSpanned(u, orientations[o].cross(u), step, 1);
    if (score.score > best.score) {
      best = score;
      if (orientation) *orientation = o;
    }
  }
  return best;
}

PatchScore PatchScorer::Plane(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                              const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                              double step) const {
  Scratch& s = ThreadScratch();
  ProjectAll(views_, x, &s.projected);
  ChooseViews(normal, &s.chosen);
  return ScoreSpanned(u, v, step, 1);
}

PatchScore PatchScorer::PlaneEitherSide(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                                        const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                                        double step, double prefilter) const {
  Scratch& s = ThreadScratch();
  ProjectAll(views_, x, &s.projected);
  PatchScore best;
  for (const Eigen::Vector3d& side : {normal, Eigen::Vector3d(-normal)}) {
    ChooseViews(side, &s.chosen);
    if (static_cast<int>(s.chosen.size()) < options_.min_views) continue;
    PatchScore score;
    if (prefilter > -1) score = ScoreSpanned(u, v, step, 2);
    if (prefilter <= -1 || score.score >= prefilter) score = ScoreSpanned(u, v, step, 1);
    if (score.score > best.score) best = score;
  }
  return best;
}

PatchScore PatchScorer::ScoreSpanned(const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                                     double step, int stride) const {
  PatchPoints points;
  points.u = step * u;
  points.v = step * v;
  points.half = options_.mu / 2;
  points.stride = stride;
  return Score(points, ThreadScratch().chosen);
}

std::vector<float> PatchScorer::AlongNormal(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                                            const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                                            double step, double curvature,
                                            const std::vector<double>& shifts) const {
  Scratch& s = ThreadScratch();
  ProjectAll(views_, x, &s.projected);
  ChooseViews(normal, &s.chosen);
  PatchGrid(options_.mu / 2, 1, u, v, step, &s.grid);
  std::vector<float> scores;
  scores.reserve(shifts.size());
  for (double shift : shifts) {
    s.offsets.clear();
    for (const Eigen::Vector3d& point : s.grid)
      s.offsets.push_back(point + (shift - 0.5 * curvature * point.squaredNorm()) * normal);
    PatchPoints points;
    points.offsets = &s.offsets;
    scores.push_back(Score(points, s.chosen).score);
  }
  return scores;
}

}  // namespace silnet::aggregator
