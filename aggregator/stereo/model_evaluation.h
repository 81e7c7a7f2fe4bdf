#pragma once
// How good a reconstructed model is (thesis ch. 5-6 evaluation, after the Middlebury
// multi-view benchmark of Seitz et al. 2006):
//   accuracy      the distance within which `accuracy_fraction` (90 %) of the model lies from
//                 the true surface;
//   completeness  the share of the true surface within a distance of the model;
// both in metres and in pixel footprints (the size of one pixel at the object, the unit the
// thesis and issue 17 state targets in), and how exactly the model explains the silhouettes.
//
// The model is sampled uniformly by area (about one point per spacing^2, spacing half a
// footprint by default, fixed seed: the figures are reproducible). The true surface is a
// point sample with unit normals (gt_surface.ply). A distance between a point and a sampled
// surface is taken to the nearest few samples' tangent planes, the in-plane offset beyond
// the sampling spacing still counted: sqrt((n.d)^2 + max(0, |d - n(n.d)| - spacing)^2), so a
// point lying on the surface measures about 0 however sparse the sample, and a point off it
// measures its offset.
//
// Silhouette consistency (issue 17's acceptance): the model rendered into a view
// (hull_reprojection.h: a pixel is covered iff its centre is inside a projected triangle)
// against the view's mask. Pixel centres lie at half a pixel inside the outline where the
// silhouette meets the background, so a silhouette pixel's distance inside the outline is its
// mask distance transform (to the nearest background pixel centre) minus 0.5, and likewise
// outside with the inverted mask. Counted: silhouette pixels at least `margin_px` inside the
// outline the model misses, and background pixels at least `margin_px` outside it the model
// covers. An exactly silhouette-consistent model has both 0.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

class NearestPoint;

// Settings of the surface measures.
struct ModelEvaluationOptions {
  double footprint = 0.0;                  // pixel footprint at the object, metres, > 0
  double sample_spacing_footprints = 0.5;  // model sampling spacing, footprints
  double accuracy_fraction = 0.9;          // share of the model within the accuracy distance
  std::vector<double> completeness_footprints = {1.0, 2.0};  // completeness distances
  double truth_spacing = 0.0;     // true points' spacing, metres; 0 = estimated
  int neighbours = 4;             // tangent planes tried per distance
  size_t max_samples = 20000000;  // cap on model samples (spacing grows beyond it)
  uint64_t random_seed = 1;       // model sampling
  int threads = 0;                // nearest-point queries' threads, 0 = all cores

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// Completeness at one distance.
struct Completeness {
  double distance_m = 0.0;
  double distance_footprints = 0.0;
  double fraction = 0.0;  // of the true points within distance_m of the model, [0, 1]
};

// The measures restricted to a region of the true surface (e.g. the concavities the visual
// hull cannot reach): completeness over the region's true points, accuracy over the model
// samples whose nearest true point lies in the region.
struct RegionEvaluation {
  std::string name;          // as the SurfaceRegion's
  size_t truth_points = 0;   // true points in the region
  size_t model_samples = 0;  // model samples nearest to one of them
  double accuracy_m = 0.0;   // infinite if no model sample is near the region
  double accuracy_footprints = 0.0;
  std::vector<Completeness> completeness;  // one per options.completeness_footprints

  // One line like ModelEvaluation::Brief, prefixed by the region's size.
  std::string Brief() const;
};

// A named part of the true surface: one flag per true point, non-zero = in the region.
struct SurfaceRegion {
  std::string name;
  std::vector<uint8_t> truth;
};

// The measures of one model.
struct ModelEvaluation {
  double footprint = 0.0;    // metres, as given
  size_t model_samples = 0;  // points sampled on the model
  size_t truth_points = 0;
  double sample_spacing = 0.0;  // of the model samples, metres
  double truth_spacing = 0.0;   // of the true points, metres (given or estimated)
  double accuracy_m = 0.0;      // accuracy_fraction of the model lies within this distance
  double accuracy_footprints = 0.0;
  double mean_distance_m = 0.0;            // mean model-to-truth distance
  std::vector<Completeness> completeness;  // one per options.completeness_footprints
  std::vector<RegionEvaluation> regions;   // one per region given, in order

  // One line: "accuracy 6.2 mm (1.06 fp), completeness 61.0 % / 73.9 % within 1 / 2 fp".
  std::string Brief() const;
  // The region of that name, or null.
  const RegionEvaluation* Region(const std::string& name) const;
};

// Points spread uniformly by area over `mesh` (about one per spacing^2, at least one per
// call with a non-empty mesh), with their triangles' unit normals; reproducible for a seed.
struct SurfaceSample {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
};
SurfaceSample SampleSurfaceBySpacing(const TriangleMesh& mesh, double spacing, uint64_t seed);

// The distances an evaluation measured, kept to measure regions later (EvaluateRegion).
struct ModelDistances {
  std::vector<double> sample_to_truth;  // per model sample, metres
  std::vector<int> nearest_truth;       // per model sample: its nearest true point
  std::vector<double> truth_to_model;   // per true point, as completeness counts it (metres;
                                        // infinite when the model is empty)
};

// The true surface prepared once for several evaluations: its points and unit normals (same
// length, referenced: they must outlive it), their nearest-point index and their spacing
// (`spacing` if > 0, otherwise estimated from the points).
class TruthSurface {
 public:
  // Indexes the points on `threads` threads (0 = all cores). CheckError if the lengths differ.
  TruthSurface(const std::vector<Eigen::Vector3d>& points,
               const std::vector<Eigen::Vector3d>& normals, double spacing, int threads);
  ~TruthSurface();
  TruthSurface(const TruthSurface&) = delete;
  TruthSurface& operator=(const TruthSurface&) = delete;

  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  const std::vector<Eigen::Vector3d>& normals() const { return normals_; }
  const NearestPoint& index() const { return *index_; }
  double spacing() const { return spacing_; }

 private:
  const std::vector<Eigen::Vector3d>& points_;
  const std::vector<Eigen::Vector3d>& normals_;
  std::unique_ptr<NearestPoint> index_;
  double spacing_ = 0.0;
};

// Accuracy and completeness of `model` (world metres) against the true surface, and restricted
// to each of `regions` (flags as long as the truth); with `distances` the distances behind
// them. Throws CheckError for invalid options or mismatched lengths; an empty model or truth
// gives infinite accuracy and zero completeness. The truth's spacing and index are the
// surface's (options.truth_spacing and options.threads served to prepare it).
ModelEvaluation EvaluateModel(const TriangleMesh& model, const TruthSurface& truth,
                              const ModelEvaluationOptions& options,
                              const std::vector<SurfaceRegion>& regions = {},
                              ModelDistances* distances = nullptr);

// EvaluateModel against the true points and unit normals, prepared for this one call with
// options.truth_spacing and options.threads.
ModelEvaluation EvaluateModel(const TriangleMesh& model,
                              const std::vector<Eigen::Vector3d>& truth_points,
                              const std::vector<Eigen::Vector3d>& truth_normals,
                              const ModelEvaluationOptions& options,
                              const std::vector<SurfaceRegion>& regions = {},
                              ModelDistances* distances = nullptr);

// The measures restricted to `region` from the `distances` of an evaluation made with the
// same options (as EvaluateModel reports them for its regions). CheckError if the region's
// length differs from the truth's.
RegionEvaluation EvaluateRegion(const SurfaceRegion& region, const ModelDistances& distances,
                                const ModelEvaluationOptions& options);

// The silhouette consistency of a model in one view.
struct SilhouetteConsistency {
  std::string camera_id;
  size_t silhouette_pixels = 0;  // mask pixels
  size_t inner_pixels = 0;       // silhouette pixels >= margin inside the outline
  size_t missed_inner = 0;       // of which the model does not cover
  // Of those, pixels no model consistent with the other views covers: their rays meet no
  // point inside every other silhouette grown by the margin (uncoverable_pixels.h).
  size_t missed_uncoverable = 0;
  size_t outer_pixels = 0;   // background pixels >= margin outside the outline
  size_t covered_outer = 0;  // of which the model covers
  // Of those, pixels covered at a surface point another view sees on one of its inner pixels
  // that no consistent model covers: the price of covering that pixel
  // (traded_outer_pixels.h).
  size_t covered_outer_traded = 0;
  size_t missed_pixels = 0;       // all silhouette pixels not covered
  size_t covered_background = 0;  // all background pixels covered
};

// Default margin of the consistency counts (issue 17: "1 px inside / outside the outline").
inline constexpr double kSilhouetteMarginPx = 1.0;

// The pixels of `mask` (CV_8UC1, non-zero = silhouette) whose centres lie at least
// `margin_px` inside its outline, which runs half a pixel beyond the outermost silhouette
// pixel centres: CV_8UC1, 255 there, 0 elsewhere.
cv::Mat InnerSilhouettePixels(const cv::Mat& mask, double margin_px = kSilhouetteMarginPx);

// Compares a coverage image (CV_8UC1, non-zero = covered) with a mask (CV_8UC1, non-zero =
// silhouette) of the same size; CheckError otherwise. `missed_inner` and `covered_outer` (may
// be null) receive the inner silhouette pixels not covered and the outer pixels covered
// (CV_8UC1, 255).
SilhouetteConsistency CompareSilhouetteConsistency(const cv::Mat& rendered, const cv::Mat& mask,
                                                   double margin_px = kSilhouetteMarginPx,
                                                   cv::Mat* missed_inner = nullptr,
                                                   cv::Mat* covered_outer = nullptr);

// The share of the silhouette pixels at least `margin_px` inside the outline of `masks`
// (CV_8UC1, non-zero = silhouette, one per camera) that `surface` misses, rendered by the
// undistorted `cameras` (0 when the masks have none).
double MissedInnerShare(const TriangleMesh& surface, const std::vector<CameraModel>& cameras,
                        const std::vector<cv::Mat>& masks, double margin_px = kSilhouetteMarginPx);

// Renders `model` into every view (RenderMeshSilhouette) and compares it with the view's mask,
// telling the missed inner pixels no consistent model covers (missed_uncoverable) and the
// outer pixels covered in trade for another view's such pixel (covered_outer_traded) apart.
// The views are measured on `threads` threads (0 = all cores), the same figures as on one.
std::vector<SilhouetteConsistency> MeasureSilhouetteConsistency(
    const TriangleMesh& model, const std::vector<StereoView>& views,
    double margin_px = kSilhouetteMarginPx, int threads = 0);

}  // namespace silnet::aggregator
