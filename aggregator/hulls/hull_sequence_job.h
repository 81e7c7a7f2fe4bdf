#pragma once
// The `hulls` job (thesis 4.2): a volumetric visual hull for every reference frame of a
// range, from a dataset folder of silhouettes (shared/io/dataset_layout.h) and a calibration.
//
// Time: reference frame r is the frame r of the reference camera — the first calibration
// camera with time_offset 0, else the first calibration camera — exposed at reference time
// T = reference.ExposureTime(r) = (r + o_ref) / fps_ref. Camera c saw that instant at its
// own fractional frame f_c = c.FrameAt(T) = T * fps_c - o_c (for equal rates and o_ref = 0:
// f_c = r - o_c). With interpolation the silhouette at f_c blends frames floor(f_c) and
// floor(f_c) + 1 through their signed distance maps (silhouette_interpolation.h); without
// it, the nearest frame round(f_c) is used.
//
// Output: OUT/frame_NNNNNN.ply (binary PLY, NNNNNN = reference frame), OUT/hulls.yaml (the
// sequence index) and, if asked, OUT/overlays/frame_NNNNNN_<camera>.png
// (hull_reprojection.h's colours).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/silhouette_source.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the job.
struct HullSequenceOptions {
  bool polyhedral = true;            // exact polyhedral hull (polyhedral_hull.h), carving the
                                     // voxels instead for a frame where it fails; false: carve
  double voxel_size = 0;             // metres; 0 = 1/200 of the first frame's bounds diagonal
  std::optional<bool> interpolate;   // sub-frame silhouettes; unset = on iff some f_c is
                                     // non-integer
  bool overlays = false;             // write OUT/overlays/*.png
  int threads = 0;                   // 0 = all cores
  double voxels_per_diagonal = 200;  // the default voxel size's divisor

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// Inputs and outputs of one run.
struct HullSequenceConfig {
  std::filesystem::path input;        // dataset folder or session store (silhouette_source.h)
  std::filesystem::path calibration;  // calibration.yaml (or ground_truth.yaml)
  std::filesystem::path output;       // created if missing
  int first_frame = 0;                // reference frames [first_frame, last_frame)
  int last_frame = 0;
  // Instead of first_frame..last_frame: every reference frame all cameras' silhouettes cover
  // (UsableReferenceFrames).
  bool every_covered_frame = false;
  HullSequenceOptions options;
};

// The hull of one reference frame. When !success nothing but `reason` is meaningful and no
// PLY file was written.
struct HullFrameResult {
  int frame = 0;      // reference frame
  double time_s = 0;  // reference time
  bool success = false;
  std::string reason;  // why there is no hull (e.g. an empty silhouette)
  std::string file;    // PLY file name inside the output folder
  size_t vertices = 0, triangles = 0;
  bool closed_manifold = false;
  double volume_m3 = 0;                 // the mesh's enclosed volume
  std::string method;                   // "polyhedral" or "voxel"
  std::string polyhedral_failure;       // why the polyhedral hull fell back to voxels, if it did
  size_t gaps_filled = 0;               // in the polyhedral hull (PolyhedralHullStats)
  bool contours_perturbed = false;      // the polyhedral hull closed on its retry
  std::vector<ViewReprojection> views;  // against the silhouettes the hull was carved from
};

// What the job did. `frames` is in reference-frame order; after cancellation it holds the
// frames finished so far (unfinished ones have success == false, reason "cancelled").
struct HullSequenceResult {
  std::vector<HullFrameResult> frames;
  double voxel_size = 0;      // metres, as used
  bool interpolated = false;  // sub-frame silhouettes used
  double seconds = 0;

  // Mean over successful frames and views of missed / spurious fractions (0 if none).
  double MeanMissed() const;
  double MeanSpurious() const;
  // Successful frames.
  size_t Succeeded() const;
  // True iff every frame succeeded with a closed manifold mesh.
  bool AllClosedManifold() const;
};

// Runs the job on the calibration's cameras (input cameras the calibration lacks, such as
// ones it could not place, are left out with a warning). Throws InputError for a calibration
// camera without silhouettes, silhouettes whose size differs from the calibration, an empty
// or out-of-range frame range, and unreadable or missing silhouettes. Per-frame failures are
// data. `progress` (may be null) counts frames and is polled for cancellation between frames.
HullSequenceResult RunHullSequenceJob(const HullSequenceConfig& config, Progress* progress);

// The same with the silhouettes from `silhouettes` rather than from config.input (which the
// index still names as the input), e.g. contours a live run holds in memory.
HullSequenceResult RunHullSequenceJob(const HullSequenceConfig& config,
                                      const SilhouetteSource& silhouettes, Progress* progress);

// Writes OUT/hulls.yaml, the sequence index of `result` (config.output is OUT). Throws
// InputError if it cannot be written.
void WriteHullIndex(const HullSequenceConfig& config, const HullSequenceResult& result);

// The reference camera's index in `cameras` by the rule above (0 if none has offset 0).
size_t ReferenceCameraIndex(const std::vector<CameraModel>& cameras);

// Reference frames [first, last) at which every camera of `cameras` has the silhouettes it
// needs in `silhouettes` (with `interpolate`, its frame after the one it saw too); nullopt
// when no reference frame is seen by every camera.
std::optional<std::pair<int, int>> UsableReferenceFrames(const SilhouetteSource& silhouettes,
                                                         const std::vector<CameraModel>& cameras,
                                                         bool interpolate);

}  // namespace silnet::aggregator
