#pragma once
// The `stereo` job (thesis ch. 5-6): a closed surface model of a still subject from a stills
// folder (stills_folder.h) and its calibration. Stages, each timed:
//   load               the views of one still (undistorted, with silhouettes) of a stills
//                      folder, or of a Middlebury folder when no calibration is given
//   visual hull        the exact polyhedral hull of the silhouettes (polyhedral_hull.h); the
//                      voxel hull at one pixel footprint, with a warning, where it fails
//   photo-consistency  votes of all view pairs on a lattice inside the hull (6.8.1)
//   graph cut          the volumetric cut between the hull and an inner offset
//                      (volumetric_graph_cut.h, 5.4.1), re-solved by silhouette steps (7.4.2)
//                      until the model covers its silhouettes (or cut with the exact
//                      silhouette constraints of Formulation I, 6.4-6.6, when asked for;
//                      Formulation II is not built). With --method adaptive the
//                      photo-consistency and graph cut stages are the adaptive tetrahedral
//                      stereo of ch. 7 instead (adaptive_stereo.h; no vote lattice)
//   refinement         the cut's surface deformed by texture and silhouette forces and
//                      remeshed (surface_refinement.h, 7.4.3), for either method, then its
//                      coverable missed silhouette pixels reached (missed_pixel_reach.h);
//                      then, when asked for, with or without refinement, the floating pieces
//                      no silhouette pixel needs removed (redundant_pieces.h)
//   evaluation         per view silhouette consistency of model and hull (model_evaluation.h)
//                      and, when the folder has gt_surface.ply (simulated stills), accuracy
//                      and completeness of model and hull against it, over the whole surface
//                      and over two regions of it: "concave" (the true points the hull misses
//                      by more than kConcaveRegionFootprints) and "t_junctions" (the surface
//                      forming the silhouettes' T-junctions, t_junction_region.h)
// Output in OUT (created if missing):
//   model.ply    the model, binary PLY (ply_io.h), written only if it is closed and manifold
//   hull.ply     the visual hull the model was cut from
//   cut.ply      the graph cut's surface, when the model is its refinement
//   stereo.yaml  settings, lattice and graph sizes, time per stage, per view silhouette
//                figures, the measures against the truth; written also after a failure,
//                with its reason
//   views/<camera>.png  per view: the photo, the model shaded from that camera and its
//                silhouette comparison side by side (model_render.h), when there is a model
//   report.html  all of the above for people (stereo_report.h), also after a failure
// Expected failures (no hull, no votes, a cut that is empty or not a closed manifold,
// cancellation) are data: success false with a reason, and no model.ply (one left by an
// earlier run in OUT is removed first).

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/stereo/adaptive_stereo.h"
#include "aggregator/stereo/exact_constraint_cut.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/photo_consistency.h"
#include "aggregator/stereo/redundant_pieces.h"
#include "aggregator/stereo/stereo_truth.h"
#include "aggregator/stereo/surface_refinement.h"
#include "aggregator/stereo/volumetric_graph_cut.h"
#include "shared/geometry/camera_model.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// The graph cut settings of the job. lambda 3 and ballooning 0.1 are measured on the
// simulator (16-camera ring, 640x480; docs/PERFORMANCE.md): lambda 1 shrinks the model more
// (completeness within 2 footprints 74 % against 84 %) for slightly better accuracy. Up to 6
// silhouette steps: on that ring the missed inner silhouette pixels go 18662, 92, 3, 0.
VolumetricGraphCutOptions StereoGraphCutDefaults();

// The reconstruction after the visual hull.
// How the uniform method's cut is held to the silhouettes.
enum class SilhouetteConstraints {
  kSteps,  // the baseline cut, then silhouette steps tying a cell per missed pixel (7.4.2):
           // the default (docs/PERFORMANCE.md)
  kExact,  // the exact constraints of Formulation I (6.4-6.6, exact_constraint_cut.h)
};

enum class StereoMethod {
  kUniform,   // votes on a uniform lattice and its volumetric graph cut (ch. 5-6): the default,
              // far cheaper on weakly textured real photographs (docs/PERFORMANCE.md)
  kAdaptive,  // the adaptive tetrahedral mesh and its dual graph cut (ch. 7): more accurate
              // on the simulated rigs, not tied to the hull's topology
};
// "uniform" or "adaptive".
std::string ToString(StereoMethod method);

// Inputs, outputs and settings of one run.
struct StereoJobConfig {
  std::filesystem::path input;         // stills folder, or Middlebury folder
  std::filesystem::path calibration;   // calibration.yaml (or ground_truth.yaml); empty: `input`
                                       // is a Middlebury folder (middlebury_dataset.h)
  std::filesystem::path output;        // created if missing
  int still = 0;                       // the still taken: stills/%06d.png, masks/%06d.png
  std::vector<std::string> leave_out;  // cameras not used, by id (each one a loaded view's)
  PhotoConsistencyOptions photo_consistency;  // threads set by `threads`
  VolumetricGraphCutOptions graph_cut = StereoGraphCutDefaults();
  StereoMethod method = StereoMethod::kUniform;
  SilhouetteConstraints constraints = SilhouetteConstraints::kSteps;  // with kUniform
  AdaptiveStereoOptions adaptive;       // with kAdaptive (threads set by `threads`)
  SurfaceRefinementOptions refinement;  // of either method's cut; 0 iterations: none
  // Remove the model's floating pieces no silhouette pixel needs (redundant_pieces.h): a
  // cleaner model, slightly more accurate and slightly less complete (docs/PERFORMANCE.md).
  bool remove_redundant_pieces = false;
  int threads = 0;  // 0 = all cores

  // True if the settings make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// Seconds per stage.
struct StereoStageTimes {
  double load = 0, hull = 0, photo_consistency = 0, graph_cut = 0, refinement = 0, evaluation = 0,
         pictures = 0, total = 0;
};

// A mesh's figures in stereo.yaml.
struct StereoMeshSummary {
  std::string file;  // inside the output folder; empty if not written
  size_t vertices = 0, triangles = 0;
  bool closed_manifold = false;
  size_t pieces = 0;    // connected parts (mesh_topology.h)
  long main_genus = 0;  // handles of the part with the most triangles
  double volume_m3 = 0;
  std::vector<SilhouetteConsistency> views;   // against each view's mask
  std::optional<ModelEvaluation> evaluation;  // against gt_surface.ply, when present

  // Over all views: inner silhouette pixels the mesh misses, outer pixels it covers, of the
  // missed ones those no model consistent with the other views covers, and of the covered
  // ones those covered in trade for another view's such pixel.
  size_t MissedInner() const;
  size_t CoveredOuter() const;
  size_t MissedUncoverable() const;
  size_t CoveredOuterTraded() const;
};

// What the job did.
struct StereoJobResult {
  bool success = false;
  std::string reason;  // when !success: the stage and why ("visual hull: ...", "cancelled")
  size_t views = 0;    // views used
  std::vector<CameraModel> cameras;   // their cameras (undistorted), in input order
  std::vector<std::string> warnings;  // the loader's and the stages'
  double footprint = 0;  // pixel footprint at the object, metres (the truth's, else estimated)
  StereoMeshSummary hull, model;
  StereoMeshSummary cut;  // the graph cut's surface when the model is its refinement
  PhotoConsistencyStats photo_consistency;
  std::array<int, 3> lattice_dims = {0, 0, 0};            // vote lattice cells along x, y, z
  double cell_size = 0;                                   // metres
  VolumetricGraphCutStats graph_cut;                      // kUniform
  std::optional<ExactConstraintStats> exact_constraints;  // kUniform with kExact
  std::optional<AdaptiveStereoStats> adaptive;            // kAdaptive
  std::optional<SurfaceRefinementStats> refinement;       // when the cut was refined
  std::optional<RedundantPieceStats> redundant_pieces;    // when asked for; timed as refinement
  StereoStageTimes seconds;
  std::vector<std::string> view_pictures;  // views/<camera>.png, relative to the output folder
};

// Width in pixels of each of the three panels of a view picture (smaller images are kept).
inline constexpr int kViewPicturePanelWidth = 480;

// Runs the job. Throws InputError for invalid settings, for what LoadStillsFolder (or
// LoadMiddlebury) rejects (unreadable calibration, a camera without any silhouette source,
// too few views), and if an output file cannot be written. `progress` (may be null) gets one
// stage after the other ("load", "visual hull", "photo-consistency", "graph cut",
// "refinement", "evaluation", "pictures") and is polled for cancellation between and within stages.
StereoJobResult RunStereoJob(const StereoJobConfig& config, Progress* progress);

// Writes OUT/stereo.yaml for `result` (config.output is OUT). Throws InputError if it cannot
// be written.
void WriteStereoSummary(const StereoJobConfig& config, const StereoJobResult& result);

}  // namespace silnet::aggregator
