#pragma once
// The true surface of simulated stills (gt_surface.ply, written by `silnet-sim stills`) and
// the regions of it the stereo job measures separately (issue 17's acceptance): "concave",
// the true points the visual hull misses by more than kConcaveRegionFootprints, and
// "t_junctions", the surface forming the silhouettes' T-junctions (t_junction_region.h).

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// Where the visual hull lies farther than this from the true surface (pixel footprints), the
// surface counts as concave: the region the issue asks stereo to be far better than the hull.
inline constexpr double kConcaveRegionFootprints = 2.0;
// Names of the regions of the true surface measured separately.
inline constexpr const char* kConcaveRegion = "concave";
inline constexpr const char* kTJunctionRegion = "t_junctions";

// Points of the true surface with unit outward normals.
struct StereoTruth {
  std::vector<Eigen::Vector3d> points, normals;
  double footprint = 0;  // metres, from the file's comments, 0 if absent
  double spacing = 0;    // metres, likewise
};

// <dir>/gt_surface.ply, or nothing if the folder has none. Throws InputError if it exists
// but cannot be read.
std::optional<StereoTruth> LoadStereoTruth(const std::filesystem::path& dir);

// The evaluation settings for `truth` at `footprint` metres, on `threads` threads (0 = all).
ModelEvaluationOptions StereoEvaluationOptions(const StereoTruth& truth, double footprint,
                                               int threads = 0);

// Accuracy and completeness against the truth of the visual hull and of the model cut from
// it, each over the whole true surface and over its concave and T-junction regions. The
// concave region comes from the hull's own distances, so the hull is measured once.
// `cut`, when given, is measured as the model is. Runs on `threads` threads (0 = all).
struct StereoTruthEvaluation {
  ModelEvaluation hull, model;
  std::optional<ModelEvaluation> cut;
};
StereoTruthEvaluation EvaluateAgainstTruth(const TriangleMesh& hull, const TriangleMesh& model,
                                           const StereoTruth& truth, double footprint,
                                           const std::vector<StereoView>& views,
                                           const TriangleMesh* cut = nullptr, int threads = 0);

}  // namespace silnet::aggregator
