#include "aggregator/pairwise/pairwise_job.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <opencv2/core/eigen.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string_view>
#include <type_traits>

#include "aggregator/pairwise/epipolar_overlay.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"
#include "shared/util/parse_number.h"

namespace silnet::aggregator {
namespace {

cv::Mat ToMat(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

// Median of (capture time - k / fps) over frames with a timestamp, in seconds.
std::optional<double> ClockOrigin(const SilhouetteSequence& s) {
  std::vector<double> origins;
  for (const SilhouetteFrame& f : s.frames) {
    if (f.capture_time_ns <= 0) continue;
    origins.push_back(static_cast<double>(f.capture_time_ns) * 1e-9 -
                      static_cast<double>(f.index) / s.fps);
  }
  if (origins.size() < 10) return std::nullopt;
  std::nth_element(origins.begin(),
                   origins.begin() + static_cast<std::ptrdiff_t>(origins.size() / 2),
                   origins.end());
  return origins[origins.size() / 2];
}

// The correspondences file of a pair's k-th alternative solution.
std::string AlternativeCsvName(const std::string& pair, int k) {
  return fmt::format("{}-alt{}.csv", pair, k);
}

// A 3x3 F from a pairs.yaml node; throws InputError naming the pair otherwise.
Eigen::Matrix3d ReadF(const cv::FileNode& node, const std::filesystem::path& path,
                      const std::string& pair) {
  const std::vector<double> f =
      ReadYamlMatrixEntries(node, "F", path.string() + ": pair " + pair, {9});
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(f.data());
}

// Writes correspondences as frame_i,frame_j,x_i,y_i,x_j,y_j (x_j at `offset`).
void WriteMatchCsv(const std::filesystem::path& file, const std::vector<TimedMatch>& matches,
                   double offset) {
  std::ofstream out(file);
  if (!out) throw InputError(file.string() + ": cannot write");
  out << "frame_i,frame_j,x_i,y_i,x_j,y_j\n";
  for (const TimedMatch& m : matches) {
    const Eigen::Vector2d xj = m.XjAt(offset);
    out << fmt::format("{},{},{:.3f},{:.3f},{:.3f},{:.3f}\n", m.frame_i, m.frame_j, m.x_i.x(),
                       m.x_i.y(), xj.x(), xj.y());
  }
}

// `field` without the spaces, tabs and carriage returns around it.
std::string_view Trimmed(std::string_view field) {
  const size_t first = field.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return field.substr(first, field.find_last_not_of(" \t\r") - first + 1);
}

// Parses the whole of `field` into `value`; false if it is not one number of that type (for a
// double also if it is not finite).
template <class T>
bool ParseField(std::string_view field, T* value) {
  if (!ParseWholeNumber(Trimmed(field), value)) return false;
  if constexpr (std::is_floating_point_v<T>) return std::isfinite(*value);
  return true;
}

// One row frame_i,frame_j,x_i,y_i,x_j,y_j; nullopt if it is not six such numbers.
std::optional<TimedMatch> ParseMatchRow(std::string_view line) {
  std::vector<std::string_view> fields;
  for (size_t start = 0;;) {
    const size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma == std::string_view::npos ? comma : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  TimedMatch m;
  double x[4];
  if (fields.size() != 6 || !ParseField(fields[0], &m.frame_i) ||
      !ParseField(fields[1], &m.frame_j))
    return std::nullopt;
  for (int k = 0; k < 4; ++k) {
    if (!ParseField(fields[static_cast<size_t>(2 + k)], &x[k])) return std::nullopt;
  }
  m.x_i = {x[0], x[1]};
  m.x_j_a = m.x_j_b = {x[2], x[3]};
  return m;
}

// Reads a correspondences file that `pairs_yaml` refers to. Throws InputError if it is
// missing or a row is not frame_i,frame_j,x_i,y_i,x_j,y_j (frames non-negative integers,
// coordinates finite); blank rows are skipped.
std::vector<TimedMatch> ReadMatchesCsv(const std::filesystem::path& file,
                                       const std::filesystem::path& pairs_yaml) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": missing (" + pairs_yaml.string() + " refers to it)");
  std::vector<TimedMatch> matches;
  std::string line;
  std::getline(in, line);  // header
  for (size_t row = 2; std::getline(in, line); ++row) {
    if (Trimmed(line).empty()) continue;
    const std::optional<TimedMatch> match = ParseMatchRow(line);
    if (!match) {
      throw InputError(
          fmt::format("{}: row {} is not frame_i,frame_j,x_i,y_i,x_j,y_j with finite coordinates",
                      file.string(), row));
    }
    matches.push_back(*match);
  }
  return matches;
}

// One solution of a pair from its pairs.yaml node, with its correspondences from `csv` when
// that is given and the solution has inliers.
PairCandidate ReadCandidate(const cv::FileNode& node, const std::filesystem::path& path,
                            const std::string& pair, const std::filesystem::path& csv) {
  PairCandidate c;
  c.F = ReadF(node, path, pair);
  c.offset = node["offset"];
  if (!std::isfinite(c.offset))
    throw InputError(path.string() + ": pair " + pair + " has a non-finite offset");
  c.model = EpipolarModel::FromFundamental(c.F, c.offset);
  c.offset_sigma = node["offset_sigma"];
  c.residual_rms = node["residual"];
  if (!(c.offset_sigma >= 0.0 && std::isfinite(c.offset_sigma)) ||
      !(c.residual_rms >= 0.0 && std::isfinite(c.residual_rms)))
    throw InputError(path.string() + ": pair " + pair +
                     " has a negative or non-finite offset_sigma or residual");
  const int inliers = node["inliers"], agreeing = node["agreeing"];
  if (inliers < 0 || agreeing < 0)
    throw InputError(path.string() + ": pair " + pair + " has a negative count");
  c.inliers = static_cast<size_t>(inliers);
  c.support = static_cast<size_t>(agreeing);
  if (!csv.empty() && c.inliers > 0) {
    c.inlier_matches = ReadMatchesCsv(csv, path);
    // A file cut short or taken from another run would silently change the network's input.
    if (c.inlier_matches.size() != c.inliers) {
      throw InputError(fmt::format("{}: {} correspondences where {} gives pair {} {} inliers",
                                   csv.string(), c.inlier_matches.size(), path.string(), pair,
                                   c.inliers));
    }
  }
  return c;
}

// The pairs of an open pairs.yaml (ReadPairsYaml).
std::vector<PairwiseResult> ReadPairs(const cv::FileStorage& fs, const std::filesystem::path& path,
                                      const std::filesystem::path& matches_dir) {
  const cv::FileNode pairs = fs["pairs"];
  if (pairs.empty() || !pairs.isSeq()) throw InputError(path.string() + ": no 'pairs' sequence");
  if (!matches_dir.empty() && !std::filesystem::is_directory(matches_dir)) {
    throw InputError(matches_dir.string() +
                     ": missing; the pairs' frontier correspondences are needed with pairs.yaml "
                     "(reuse a whole `pairs` output folder)");
  }
  std::vector<PairwiseResult> out;
  for (const cv::FileNode& node : pairs) {
    PairwiseResult p;
    p.camera_i = static_cast<std::string>(node["i"]);
    p.camera_j = static_cast<std::string>(node["j"]);
    const std::string status = node["status"];
    p.status = status == "ok"           ? PairStatus::kOk
               : status == "degenerate" ? PairStatus::kDegenerate
               : status == "ambiguous"  ? PairStatus::kAmbiguous
                                        : PairStatus::kFailed;
    p.reason = static_cast<std::string>(node["reason"]);
    const std::string name = p.camera_i + "-" + p.camera_j;
    if (p.camera_i.empty() || p.camera_j.empty() || p.camera_i == p.camera_j)
      throw InputError(path.string() + ": pair '" + name + "' needs two different cameras");
    const auto csv = [&](const std::string& file) {
      return matches_dir.empty() ? std::filesystem::path() : matches_dir / file;
    };
    p.Adopt(ReadCandidate(node, path, name, csv(name + ".csv")));
    p.spread_score = node["spread_score"];
    p.epipole_inside_fraction = node["epipole_inside_fraction"];
    p.best_local_support = node["best_local_support"];
    int k = 0;
    for (const cv::FileNode& a : node["alternatives"])
      p.alternatives.push_back(ReadCandidate(a, path, name, csv(AlternativeCsvName(name, k++))));
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

size_t PairwiseJobResult::ok() const {
  size_t count = 0;
  for (const PairwiseResult& p : pairs)
    count += p.status == PairStatus::kOk ? 1 : 0;
  return count;
}

std::optional<double> OffsetFromTimestamps(const SilhouetteSequence& i,
                                           const SilhouetteSequence& j) {
  const auto a = ClockOrigin(i), b = ClockOrigin(j);
  if (!a || !b) return std::nullopt;
  // a + k / f = b + m / f  =>  m = k + (a - b) f.
  return (*a - *b) * i.fps;
}

PairwiseJobResult EstimateAllPairs(const std::vector<SilhouetteSequence>& sequences,
                                   const PairwiseJobOptions& options, Progress* progress) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < sequences.size(); ++i) {
    for (size_t j = i + 1; j < sequences.size(); ++j)
      pairs.emplace_back(i, j);
  }
  PairwiseJobResult result;
  result.pairs.resize(pairs.size());
  ParallelFor(pairs.size(), options.threads, [&](size_t p) {
    if (progress != nullptr && progress->cancelled()) return;
    const auto [i, j] = pairs[p];
    PairwiseOptions pair = options.pair;
    pair.seed = options.pair.seed * 1000003u + p;
    if (options.use_timestamps && !pair.synchronized) {
      pair.offset_prior = OffsetFromTimestamps(sequences[i], sequences[j]);
      pair.prior_sigma = options.timestamp_sigma;
    }
    result.pairs[p] = EstimatePair(sequences[i], sequences[j], pair, progress);
    const PairwiseResult& r = result.pairs[p];
    spdlog::info("pair {}-{}: {}{}{} ({} inliers, offset {:+.3f} +- {:.3f}, {:.1f} s)", r.camera_i,
                 r.camera_j, ToString(r.status), r.reason.empty() ? "" : ": ", r.reason, r.inliers,
                 r.offset, r.offset_sigma, r.seconds);
    if (progress != nullptr) progress->Advance();
  });
  if (progress != nullptr) progress->Finish();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void WritePairsYaml(const std::filesystem::path& path, const PairwiseJobResult& result) {
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw InputError(path.string() + ": cannot write");
  fs << "silnet_pairs_version" << 1;
  fs << "seconds" << result.seconds;
  fs << "pairs"
     << "[";
  for (const PairwiseResult& p : result.pairs) {
    fs << "{"
       << "i" << p.camera_i << "j" << p.camera_j << "status" << ToString(p.status) << "reason"
       << p.reason;
    fs << "F" << ToMat(p.F) << "epipole_i" << ToMat(p.model.pencil_i.e) << "epipole_j"
       << ToMat(p.model.pencil_j.e);
    fs << "offset" << p.offset << "offset_sigma" << p.offset_sigma << "inliers"
       << static_cast<int>(p.inliers);
    fs << "residual" << p.residual_rms << "spread_score" << p.spread_score;
    fs << "epipole_inside_fraction" << p.epipole_inside_fraction << "tau0" << p.tau0
       << "best_local_support" << p.best_local_support;
    fs << "iterations" << static_cast<double>(p.iterations) << "candidates"
       << static_cast<int>(p.candidates);
    fs << "agreeing" << static_cast<int>(p.candidates_agreeing) << "seconds" << p.seconds;
    if (!p.alternatives.empty()) {
      fs << "alternatives"
         << "[";
      for (const PairCandidate& a : p.alternatives) {
        fs << "{"
           << "F" << ToMat(a.F) << "offset" << a.offset << "offset_sigma" << a.offset_sigma
           << "inliers" << static_cast<int>(a.inliers) << "residual" << a.residual_rms << "agreeing"
           << static_cast<int>(a.support) << "}";
      }
      fs << "]";
    }
    fs << "}";
  }
  fs << "]";
}

std::vector<PairwiseResult> ReadPairsYaml(const std::filesystem::path& path,
                                          const std::filesystem::path& matches_dir) {
  cv::FileStorage fs = OpenYamlForReading(path);
  return ReadYamlGuarded(path, "malformed", [&] { return ReadPairs(fs, path, matches_dir); });
}

void WriteMatchesCsv(const std::filesystem::path& dir, const PairwiseJobResult& result) {
  std::filesystem::create_directories(dir);
  for (const PairwiseResult& p : result.pairs) {
    const std::string name = p.camera_i + "-" + p.camera_j;
    if (!p.inlier_matches.empty()) WriteMatchCsv(dir / (name + ".csv"), p.inlier_matches, p.offset);
    for (size_t k = 0; k < p.alternatives.size(); ++k) {
      const PairCandidate& a = p.alternatives[k];
      if (!a.inlier_matches.empty())
        WriteMatchCsv(dir / AlternativeCsvName(name, static_cast<int>(k)), a.inlier_matches,
                      a.offset);
    }
  }
}

PairwiseJobResult RunPairsJob(const PairsJobConfig& config, Progress* progress) {
  SequenceLoadOptions load;
  load.max_frames = config.max_frames;
  load.allow_warmup = config.options.pair.allow_warmup;
  load.threads = config.options.threads;
  load.mask_video = config.mask_video;
  load.frame_video = config.frame_video;
  SequenceSource source = SequenceSource::kSessionLogs;
  const std::vector<SilhouetteSequence> sequences = LoadSequences(config.input, load, &source);
  if (sequences.size() < 2) throw InputError(config.input.string() + ": fewer than two cameras");
  for (const SilhouetteSequence& s : sequences) {
    spdlog::info("{}: {} frames, {} usable, {}x{} at {} fps", s.camera_id, s.frames.size(),
                 s.UsableCount(), s.width, s.height, s.fps);
  }
  return RunPairsOnSequences(config, sequences, source, progress);
}

PairwiseJobResult RunPairsOnSequences(const PairsJobConfig& config,
                                      const std::vector<SilhouetteSequence>& sequences,
                                      SequenceSource source, Progress* progress) {
  std::filesystem::create_directories(config.output);
  if (progress != nullptr)
    progress->Restart("pairs", sequences.size() * (sequences.size() - 1) / 2);
  PairwiseJobResult result = EstimateAllPairs(sequences, config.options, progress);
  WritePairsYaml(config.output / "pairs.yaml", result);
  WriteMatchesCsv(config.output / "matches", result);
  if (config.overlays != OverlaySelection::kNone) {
    std::filesystem::create_directories(config.output / "overlays");
    const DatasetLayout layout(config.input);
    auto image = [&](const SilhouetteSequence& s, uint64_t frame) {
      if (source == SequenceSource::kSessionLogs || source == SequenceSource::kMaskVideo ||
          source == SequenceSource::kFrameVideo)
        return cv::Mat();
      const auto path = source == SequenceSource::kMaskDataset
                            ? layout.MaskPath(s.camera_id, static_cast<int>(frame))
                            : layout.FramePath(s.camera_id, static_cast<int>(frame));
      return cv::imread(path.string(), cv::IMREAD_COLOR);
    };
    for (const PairwiseResult& p : result.pairs) {
      if (config.overlays == OverlaySelection::kOk && p.status != PairStatus::kOk) continue;
      const auto& si = *std::find_if(sequences.begin(), sequences.end(),
                                     [&](const auto& s) { return s.camera_id == p.camera_i; });
      const auto& sj = *std::find_if(sequences.begin(), sequences.end(),
                                     [&](const auto& s) { return s.camera_id == p.camera_j; });
      const uint64_t frame = OverlayFrame(p, si, sj);
      const uint64_t frame_j =
          static_cast<uint64_t>(std::max(0.0, std::round(static_cast<double>(frame) + p.offset)));
      const cv::Mat overlay =
          DrawPairOverlay(p, si, sj, frame, image(si, frame), image(sj, frame_j));
      const auto path = config.output / "overlays" / (p.camera_i + "-" + p.camera_j + ".png");
      if (!cv::imwrite(path.string(), overlay)) throw InputError(path.string() + ": cannot write");
    }
  }
  return result;
}

}  // namespace silnet::aggregator
