#include "aggregator/calibration/calibrate_job.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <opencv2/core/persistence.hpp>

#include "aggregator/calibration/frontier_rematching.h"
#include "aggregator/report/calibration_report.h"
#include "aggregator/report/colmap_export.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Camera templates from the sequences; with known intrinsics, K and dist from the file.
std::vector<CameraModel> CameraTemplates(const std::vector<SilhouetteSequence>& sequences,
                                         const std::filesystem::path& intrinsics) {
  std::vector<CameraModel> known;
  if (!intrinsics.empty()) known = LoadCalibration(intrinsics);
  std::vector<CameraModel> cameras;
  for (const SilhouetteSequence& s : sequences) {
    CameraModel c;
    c.id = s.camera_id;
    c.width = s.width;
    c.height = s.height;
    c.fps = s.fps;
    if (!intrinsics.empty()) {
      const auto it = std::find_if(known.begin(), known.end(),
                                   [&](const CameraModel& k) { return k.id == s.camera_id; });
      if (it == known.end())
        throw InputError(intrinsics.string() + ": no intrinsics for camera " + s.camera_id);
      if (it->width != s.width || it->height != s.height) {
        throw InputError(intrinsics.string() + ": camera " + s.camera_id + " is " +
                         std::to_string(it->width) + "x" + std::to_string(it->height) +
                         " there but its frames are " + std::to_string(s.width) + "x" +
                         std::to_string(s.height));
      }
      c.K = it->K;
      c.dist = it->dist;
    }
    cameras.push_back(c);
  }
  return cameras;
}

// Puts the known lens distortion back on a network calibrated on undistorted silhouettes:
// the cameras get their distortion again and the frontier observations their raw pixels.
void RestoreDistortion(const std::vector<CameraModel>& cameras, NetworkCalibration* calibration) {
  for (size_t c = 0; c < cameras.size(); ++c)
    calibration->cameras[c].dist = cameras[c].dist;
  for (FrontierPoint& point : calibration->points) {
    for (FrontierObservation& o : point.views)
      o.pixel = DistortPixel(cameras[o.camera], o.pixel);
  }
}

}  // namespace

CalibrateJobResult RunCalibrateJob(const CalibrateJobConfig& config, Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  if (!config.ground_truth.empty() && !std::filesystem::exists(config.ground_truth))
    throw InputError(config.ground_truth.string() + ": no such ground-truth calibration");
  SequenceLoadOptions load;
  load.first_frame = config.first_frame;
  load.max_frames = config.max_frames;
  load.allow_warmup = config.pairwise.pair.allow_warmup;
  load.threads = config.pairwise.threads;
  load.mask_video = config.mask_video;
  load.frame_video = config.frame_video;
  SequenceSource source = SequenceSource::kSessionLogs;
  std::vector<SilhouetteSequence> sequences = LoadSequences(config.input, load, &source);
  if (sequences.size() < 3)
    throw InputError(config.input.string() + ": a network calibration needs at least 3 cameras");
  const std::vector<CameraModel> cameras = CameraTemplates(sequences, config.intrinsics);
  // Known lens distortion is taken out of the silhouettes before any estimation: the pairwise
  // and network stages then fit pinhole geometry, and the distortion is put back at the end.
  std::vector<CameraModel> pinhole = cameras;
  const bool undistort =
      std::any_of(cameras.begin(), cameras.end(), [](const auto& c) { return c.HasDistortion(); });
  if (undistort) {
    ParallelFor(sequences.size(), 0, [&](size_t c) {
      sequences[c] = UndistortSequence(sequences[c], cameras[c]);
      pinhole[c].dist.setZero();
    });
    spdlog::info("silhouettes undistorted with the given intrinsics before estimation");
  }
  std::filesystem::create_directories(config.output);

  CalibrateJobResult result;
  if (!config.reuse_pairs.empty()) {
    result.pairs.pairs =
        ReadPairsYaml(config.reuse_pairs / "pairs.yaml", config.reuse_pairs / "matches");
    spdlog::info("reusing {} pairwise results from {}", result.pairs.pairs.size(),
                 config.reuse_pairs.string());
  } else {
    PairsJobConfig pairs;
    pairs.input = config.input;
    pairs.output = config.output;
    pairs.options = config.pairwise;
    const bool distortion_in_silhouettes =
        !undistort &&
        (config.calibration.intrinsics.radial_terms > 0 || config.calibration.detect_distortion);
    if (distortion_in_silhouettes &&
        pairs.options.pair.local_fit_px < PairwiseOptions::kDistortedLocalFitPx) {
      // The distortion to be estimated (or looked for) may still be in the silhouettes: no
      // pinhole F fits them as closely as the local fits otherwise ask for.
      pairs.options.pair.local_fit_px = PairwiseOptions::kDistortedLocalFitPx;
      spdlog::info("silhouettes that may carry lens distortion: local fits accept {:.1f} px",
                   pairs.options.pair.local_fit_px);
    }
    pairs.overlays = OverlaySelection::kNone;
    if (progress) progress->Restart("pairs", sequences.size() * (sequences.size() - 1) / 2);
    result.pairs = RunPairsOnSequences(pairs, sequences, source, progress);
    spdlog::info("pairs: {} of {} ok in {:.1f} s", result.pairs.ok(), result.pairs.pairs.size(),
                 result.pairs.seconds);
  }
  if (progress && progress->cancelled()) throw InputError("cancelled");

  CalibrationOptions options = config.calibration;
  options.known_intrinsics = !config.intrinsics.empty();
  result.calibration = CalibrateNetwork(pinhole, result.pairs.pairs, &sequences, options, progress);
  if (undistort) RestoreDistortion(cameras, &result.calibration);
  const NetworkCalibration& calibration = result.calibration;

  const std::filesystem::path truth =
      config.ground_truth.empty() ? config.input / "ground_truth.yaml" : config.ground_truth;
  if (config.compare_ground_truth && std::filesystem::exists(truth) &&
      calibration.PlacedCount() >= 3) {
    // A simulated capture may have cameras that moved: compare with them as they were when
    // the frames began.
    result.errors = CompareWithGroundTruth(calibration.cameras, calibration.PlacedMask(),
                                           LoadCamerasAtFrame(truth, config.first_frame));
  }
  if (calibration.PlacedCount() > 0) {
    SaveCalibration(config.output / "calibration.yaml", calibration.PlacedCameras());
    WriteColmapText(config.output / "colmap", calibration);
  }
  WriteCalibrationSummary(config.output / "calibration_summary.yaml", result);
  if (config.report) WriteCalibrationReport(config.output / "report", calibration, result.errors);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void WriteCalibrationSummary(const std::filesystem::path& path, const CalibrateJobResult& result) {
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw InputError(path.string() + ": cannot write");
  const NetworkCalibration& c = result.calibration;
  fs << "format_version" << 1;
  fs << "cameras_placed" << static_cast<int>(c.PlacedCount());
  fs << "cameras_total" << static_cast<int>(c.cameras.size());
  fs << "reprojection_rms_px" << c.rms_px << "reprojection_median_px" << c.median_px;
  fs << "known_intrinsics" << c.known_intrinsics;
  fs << "cameras"
     << "[";
  for (size_t k = 0; k < c.cameras.size(); ++k) {
    const CameraPlacement& p = c.placement[k];
    fs << "{"
       << "id" << c.cameras[k].id << "placed" << p.placed;
    if (p.placed) {
      fs << "added_by" << p.added_by << "observations" << static_cast<int>(p.observations)
         << "rms_px" << p.rms_px << "median_px" << p.median_px;
      if (p.uncertainty.estimated) {
        const CameraUncertainty& u = p.uncertainty;
        fs << "uncertainty"
           << "{"
           << "rotation_deg" << u.rotation_deg << "center_rel" << u.center_rel << "focal_rel"
           << u.focal_rel << "principal_px" << u.principal_px << "}";
      }
    } else {
      fs << "reason" << p.reason;
    }
    if (k < c.motion.size() && c.motion[k].frames > 0) {
      const MotionCoverage& m = c.motion[k];
      fs << "motion"
         << "{"
         << "sufficient" << m.sufficient << "image_share" << m.image_share << "direction_share"
         << m.direction_share << "moving_frames" << static_cast<int>(m.moving_frames)
         << "usable_frames" << static_cast<int>(m.usable_frames) << "frames"
         << static_cast<int>(m.frames) << "}";
    }
    if (k < c.sync.offsets.size()) {
      fs << "synchronised" << static_cast<bool>(c.sync.synchronised[k]) << "time_offset"
         << c.sync.offsets[k] << "time_offset_sigma" << c.sync.sigmas[k];
      if (!c.sync.reasons[k].empty()) fs << "sync_reason" << c.sync.reasons[k];
    }
    fs << "}";
  }
  fs << "]";
  fs << "sync_reference" << static_cast<int>(c.sync.reference);
  fs << "sync_rms_residual" << c.sync.rms_residual;
  fs << "sync_edges"
     << "[";
  for (const SyncEdgeResult& e : c.sync.edges) {
    fs << "{"
       << "i" << c.cameras[e.edge.i].id << "j" << c.cameras[e.edge.j].id << "offset"
       << e.edge.offset << "sigma" << e.edge.sigma << "used" << e.used << "residual" << e.residual
       << "cycles" << static_cast<int>(e.cycles) << "cycles_failed"
       << static_cast<int>(e.cycles_failed);
    if (!e.rejection.empty()) fs << "rejection" << e.rejection;
    fs << "}";
  }
  fs << "]";
  fs << "stages"
     << "[";
  for (const CalibrationStage& s : c.stages) {
    fs << "{"
       << "name" << s.name << "rms_px" << s.rms_px << "seconds" << s.seconds << "detail" << s.detail
       << "}";
  }
  fs << "]";
  fs << "pair_checks"
     << "[";
  for (const PairCheck& p : c.pairs) {
    fs << "{"
       << "i" << c.cameras[p.i].id << "j" << c.cameras[p.j].id << "pairwise_status"
       << ToString(p.pairwise_status) << "used" << p.used << "distance_px" << p.distance_px
       << "corrected" << p.corrected << "note" << p.note << "}";
  }
  fs << "]";
  if (result.errors) {
    const CalibrationErrors& e = *result.errors;
    fs << "ground_truth"
       << "{"
       << "median_focal_rel" << e.median_focal_rel << "max_focal_rel" << e.max_focal_rel
       << "median_rotation_deg" << e.median_rotation_deg << "max_rotation_deg" << e.max_rotation_deg
       << "median_center_rel" << e.median_center_rel << "max_center_rel" << e.max_center_rel
       << "median_offset_frames" << e.median_offset_frames << "max_offset_frames"
       << e.max_offset_frames << "median_k1_error" << e.median_k1_error << "}";
  }
}

}  // namespace silnet::aggregator
