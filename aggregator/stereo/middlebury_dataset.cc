#include "aggregator/stereo/middlebury_dataset.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <array>
#include <fstream>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>

#include "aggregator/stereo/stills_folder.h"
#include "node/segmentation/mask_cleanup.h"
#include "shared/geometry/nearest_rotation.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

namespace fs = std::filesystem;

// The one file in `folder` whose name ends in `suffix`, or an empty path.
fs::path FindBySuffix(const fs::path& folder, const std::string& suffix) {
  fs::path found;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.size() < suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    if (!found.empty())
      throw InputError(fmt::format("{}: more than one *{} file", folder.string(), suffix));
    found = entry.path();
  }
  return found;
}

// Image names listed one per line in `path`.
std::set<std::string> ReadNameList(const fs::path& path) {
  std::ifstream in(path);
  std::set<std::string> names;
  std::string name;
  while (in >> name)
    names.insert(name);
  return names;
}

// The mask with the components smaller than `fraction` of the largest one removed.
cv::Mat KeepLargeComponents(const cv::Mat& mask, double fraction) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  int largest = 0;
  for (int i = 1; i < count; ++i)
    largest = std::max(largest, stats.at<int>(i, cv::CC_STAT_AREA));
  cv::Mat out = cv::Mat::zeros(mask.size(), CV_8UC1);
  for (int i = 1; i < count; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) >= fraction * largest) out.setTo(255, labels == i);
  }
  return out;
}

// Fills the holes of `mask` (background components not touching the image border) whose
// median `brightest` exceeds the `percentile` of the outer background's: a shadow pocket on
// the subject is brighter than the backdrop seen through a real gap. Returns the holes filled.
int FillShadowPockets(const cv::Mat& brightest, double percentile, cv::Mat* mask) {
  cv::Mat labels;
  const int count = cv::connectedComponents(*mask == 0, labels, 4, CV_32S);
  if (count <= 1) return 0;
  std::vector<bool> outer(static_cast<size_t>(count), false);
  const auto mark_outer = [&](int row, int col) {
    outer[static_cast<size_t>(labels.at<int>(row, col))] = true;
  };
  for (int col = 0; col < labels.cols; ++col) {
    mark_outer(0, col);
    mark_outer(labels.rows - 1, col);
  }
  for (int row = 0; row < labels.rows; ++row) {
    mark_outer(row, 0);
    mark_outer(row, labels.cols - 1);
  }
  // Brightness histograms: one per hole, one of the whole outer background.
  std::vector<std::array<int, 256>> histograms(static_cast<size_t>(count) + 1,
                                               std::array<int, 256>{});
  const size_t outer_histogram = static_cast<size_t>(count);
  for (int row = 0; row < labels.rows; ++row) {
    for (int col = 0; col < labels.cols; ++col) {
      const int label = labels.at<int>(row, col);
      if (label == 0) continue;
      const size_t h =
          outer[static_cast<size_t>(label)] ? outer_histogram : static_cast<size_t>(label);
      ++histograms[h][brightest.at<uint8_t>(row, col)];
    }
  }
  const auto quantile = [](const std::array<int, 256>& histogram, double q) {
    const double total = std::accumulate(histogram.begin(), histogram.end(), 0.0);
    double below = 0;
    for (int value = 0; value < 256; ++value) {
      below += histogram[static_cast<size_t>(value)];
      if (below >= q * total) return value;
    }
    return 255;
  };
  const int backdrop = quantile(histograms[outer_histogram], percentile);
  int filled = 0;
  for (int label = 1; label < count; ++label) {
    if (outer[static_cast<size_t>(label)] ||
        quantile(histograms[static_cast<size_t>(label)], 0.5) <= backdrop)
      continue;
    mask->setTo(255, labels == label);
    ++filled;
  }
  return filled;
}

}  // namespace

bool DarkBackgroundOptions::IsValid(std::string* reason) const {
  if (threshold < 0 || threshold > 254) {
    *reason = "threshold must lie in [0, 254]";
    return false;
  }
  if (coloured_threshold < 0 || coloured_threshold > 254 || !(min_saturation >= 0)) {
    *reason = "coloured_threshold must lie in [0, 254] and min_saturation be >= 0";
    return false;
  }
  if (!(shadow_pocket_percentile >= 0)) {
    *reason = "shadow_pocket_percentile must be >= 0";
    return false;
  }
  if (open_radius < 0 || close_radius < 0 || max_hole_area < 0) {
    *reason = "radii and hole area must be >= 0";
    return false;
  }
  if (!(min_component_fraction >= 0 && min_component_fraction <= 1)) {
    *reason = "min_component_fraction must lie in [0, 1]";
    return false;
  }
  return true;
}

cv::Mat ThresholdDarkBackground(const cv::Mat& image, const DarkBackgroundOptions& options) {
  SILNET_CHECK_MSG(image.type() == CV_8UC3, "ThresholdDarkBackground needs a BGR image");
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  const cv::Mat brightest = cv::max(cv::max(channels[0], channels[1]), channels[2]);
  const cv::Mat darkest = cv::min(cv::min(channels[0], channels[1]), channels[2]);
  cv::Mat spread;
  cv::subtract(brightest, darkest, spread, cv::noArray(), CV_32F);
  cv::Mat brightest_float;
  brightest.convertTo(brightest_float, CV_32F);
  const cv::Mat coloured = (brightest > options.coloured_threshold) &
                           (spread > options.min_saturation * brightest_float);
  cv::Mat mask = (brightest > options.threshold) | coloured;
  node::SegmentationOptions cleanup;
  cleanup.open_radius = options.open_radius;
  cleanup.close_radius = options.close_radius;
  cleanup.min_blob_area = 1;
  cleanup.max_hole_area = 0;
  node::CleanMask(&mask, cleanup);
  mask = KeepLargeComponents(mask, options.min_component_fraction);
  cleanup.open_radius = 0;
  cleanup.close_radius = 0;
  cleanup.max_hole_area = options.max_hole_area;
  node::CleanMask(&mask, cleanup);
  if (options.shadow_pocket_percentile <= 1)
    FillShadowPockets(brightest, options.shadow_pocket_percentile, &mask);
  return mask;
}

DarkBackgroundOptions MiddleburyPreset(const std::string& prefix) {
  DarkBackgroundOptions options;
  if (prefix.starts_with("dino")) {
    options.threshold = 40;
  } else if (prefix.starts_with("temple")) {
    options.threshold = 90;
    options.coloured_threshold = 30;
    options.min_saturation = 0.45;
  }
  return options;
}

StereoViews LoadMiddlebury(const fs::path& folder,
                           const std::optional<DarkBackgroundOptions>& chosen) {
  if (!fs::is_directory(folder))
    throw InputError(fmt::format("{} is not a folder", folder.string()));
  const fs::path par = FindBySuffix(folder, "_par.txt");
  if (par.empty()) throw InputError(fmt::format("{}: no *_par.txt file", folder.string()));
  const std::string file = par.filename().string();
  const DarkBackgroundOptions options =
      chosen ? *chosen : MiddleburyPreset(file.substr(0, file.size() - 8));
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("dark background options: " + reason);
  const fs::path good_list = FindBySuffix(folder, "_good_silhouette_images.txt");
  const std::set<std::string> good =
      good_list.empty() ? std::set<std::string>{} : ReadNameList(good_list);
  std::ifstream in(par);
  int count = 0;
  if (!(in >> count) || count <= 0)
    throw InputError(fmt::format("{}: bad view count", par.string()));
  StereoViews result;
  for (int v = 0; v < count; ++v) {
    std::string name;
    Eigen::Matrix3d k, r;
    Eigen::Vector3d t;
    in >> name;
    for (int i = 0; i < 9; ++i)
      in >> k(i / 3, i % 3);
    for (int i = 0; i < 9; ++i)
      in >> r(i / 3, i % 3);
    for (int i = 0; i < 3; ++i)
      in >> t(i);
    if (!in) throw InputError(fmt::format("{}: view {} is malformed", par.string(), v + 1));
    // The dino's rotations are orthonormal to about 1.5e-6 only: replaced by the nearest
    // rotation (a change of under 0.01 px in the image).
    const std::optional<Eigen::Matrix3d> rotation = NearestRotation(r, kPrintedRotationTolerance);
    if (!(k(0, 0) > 0 && k(1, 1) > 0) || !rotation)
      throw InputError(fmt::format("{}: {} has no valid K or R", par.string(), name));
    StereoView view;
    const fs::path image_path = folder / name;
    view.image = cv::imread(image_path.string(), cv::IMREAD_COLOR);
    if (view.image.empty())
      throw InputError(fmt::format("cannot read or decode {}", image_path.string()));
    view.camera.id = fs::path(name).stem().string();
    view.camera.width = view.image.cols;
    view.camera.height = view.image.rows;
    view.camera.K = k;
    view.camera.R = *rotation;
    view.camera.t = t;
    view.mask = ThresholdDarkBackground(view.image, options);
    view.silhouette_source = MaskOrigin::kThreshold;
    if (!good.empty() && !good.contains(name)) {
      result.warnings.push_back(
          fmt::format("{}: not listed in {}", view.camera.id, good_list.filename().string()));
    }
    result.views.push_back(std::move(view));
  }
  return result;
}

fs::path WriteMiddleburyAsStillsFolder(const fs::path& folder, const fs::path& out,
                                       const std::optional<DarkBackgroundOptions>& options) {
  return WriteStillsFolder(out, LoadMiddlebury(folder, options));
}

}  // namespace silnet::aggregator
