#pragma once
// The pairwise job: the epipolar geometry and time offset of every camera pair of a capture,
// pairs estimated in parallel with progress; results written as pairs.yaml and the inlier
// frontier correspondences as CSV files (DESIGN.md "Pairwise results").

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"

namespace silnet::aggregator {

// Settings of the job.
struct PairwiseJobOptions {
  PairwiseOptions pair;          // per-pair settings (each pair gets its own seed from pair.seed)
  int threads = 0;               // pairs estimated at once (0 = all cores)
  bool use_timestamps = false;   // narrow each offset search with the capture timestamps
  double timestamp_sigma = 2.0;  // frames; how far the timestamp prior may be off
};

// All pairs of a capture.
struct PairwiseJobResult {
  std::vector<PairwiseResult> pairs;
  double seconds = 0.0;
  size_t ok() const;
};

// The offset that the capture timestamps of two sequences imply (frame k of i meets frame
// k + offset of j), from the median clock origin of each; nullopt without timestamps.
std::optional<double> OffsetFromTimestamps(const SilhouetteSequence& i,
                                           const SilhouetteSequence& j);

// Estimates every pair (i < j in the sequences' order). Honours cancellation.
PairwiseJobResult EstimateAllPairs(const std::vector<SilhouetteSequence>& sequences,
                                   const PairwiseJobOptions& options, Progress* progress = nullptr);

// Writes pairs.yaml: per pair i, j, status, reason, F (x_j^T F x_i = 0), epipoles, offset,
// offset_sigma, inliers, residual, spread score, best local support, timing. Throws
// InputError if unwritable.
void WritePairsYaml(const std::filesystem::path& path, const PairwiseJobResult& result);

// Reads pairs.yaml (the inlier correspondences are read from `matches_dir` when given).
// Throws InputError for a missing or malformed file.
std::vector<PairwiseResult> ReadPairsYaml(const std::filesystem::path& path,
                                          const std::filesystem::path& matches_dir = {});

// Writes each pair's inlier frontier correspondences to <dir>/<i>-<j>.csv
// (frame_i,frame_j,x_i,y_i,x_j,y_j at the pair's offset).
void WriteMatchesCsv(const std::filesystem::path& dir, const PairwiseJobResult& result);

// Which pairs get a PNG overlay.
enum class OverlaySelection { kNone, kOk, kAll };

// `silnet-aggregator pairs`: load the input, estimate every pair, write pairs.yaml,
// matches/<i>-<j>.csv and overlays/<i>-<j>.png into `output`.
struct PairsJobConfig {
  std::filesystem::path input;
  std::filesystem::path output;
  PairwiseJobOptions options;
  int max_frames = 0;       // 0 = all
  std::string mask_video;   // each camera folder's mask video, when the input is one
  std::string frame_video;  // each camera folder's colour video, when the input is one
  OverlaySelection overlays = OverlaySelection::kOk;
};

// Runs the job; throws InputError for unreadable input or unwritable output.
PairwiseJobResult RunPairsJob(const PairsJobConfig& config, Progress* progress);

// The job on sequences already loaded from config.input (`source` says what they came from,
// for the overlays' background images).
PairwiseJobResult RunPairsOnSequences(const PairsJobConfig& config,
                                      const std::vector<SilhouetteSequence>& sequences,
                                      SequenceSource source, Progress* progress);

}  // namespace silnet::aggregator
