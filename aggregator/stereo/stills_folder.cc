#include "aggregator/stereo/stills_folder.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <set>

#include "aggregator/stereo/undistort_view.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/io/png_writer.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

namespace fs = std::filesystem;

// Paths of one camera's files in the folder.
struct CameraFiles {
  fs::path still;
  fs::path mask;
  fs::path background;
};

CameraFiles FilesOf(const fs::path& dir, const std::string& id, int frame) {
  const std::string name = DatasetLayout::ImageName(frame);
  return {dir / id / "stills" / name, dir / id / "masks" / name, dir / id / "background.png"};
}

// The image at `path` decoded with `flags`, or nullopt with `*problem` set when it cannot be
// read or decoded, or is not `size`.
std::optional<cv::Mat> ReadImage(const fs::path& path, int flags, const cv::Size& size,
                                 std::string* problem) {
  cv::Mat image;
  try {
    image = cv::imread(path.string(), flags);
  } catch (const cv::Exception&) {
    image.release();
  }
  if (image.empty()) {
    *problem = fmt::format("cannot read or decode {}", path.string());
    return std::nullopt;
  }
  if (image.size() != size) {
    *problem = fmt::format("{} is {}x{}, the calibration says {}x{}", path.string(), image.cols,
                           image.rows, size.width, size.height);
    return std::nullopt;
  }
  return image;
}

// Ids of the sub-folders of `dir` that hold a stills/ folder.
std::vector<std::string> FoldersWithStills(const fs::path& dir) {
  std::vector<std::string> ids;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_directory() && fs::is_directory(entry.path() / "stills"))
      ids.push_back(entry.path().filename().string());
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

// Loads one camera's view, or nullopt with `*problem` set when it is left out.
std::optional<StereoView> LoadView(const fs::path& dir, const CameraModel& camera,
                                   const StillsFolderOptions& options, std::string* problem) {
  const CameraFiles files = FilesOf(dir, camera.id, options.frame);
  const cv::Size size(camera.width, camera.height);
  if (!fs::exists(files.still)) {
    *problem = fmt::format("no still {}", files.still.string());
    return std::nullopt;
  }
  StereoView view;
  view.camera = camera;
  const std::optional<cv::Mat> still = ReadImage(files.still, cv::IMREAD_COLOR, size, problem);
  if (!still) return std::nullopt;
  view.image = *still;
  if (fs::exists(files.mask)) {
    const std::optional<cv::Mat> mask = ReadImage(files.mask, cv::IMREAD_GRAYSCALE, size, problem);
    if (!mask) return std::nullopt;
    view.nonbinary_mask_pixels =
        static_cast<size_t>(cv::countNonZero((*mask != 0) & (*mask != 255)));
    view.mask = *mask >= 128;
    view.silhouette_source = MaskOrigin::kMaskFile;
  } else if (fs::exists(files.background)) {
    const std::optional<cv::Mat> background =
        ReadImage(files.background, cv::IMREAD_COLOR, size, problem);
    if (!background) return std::nullopt;
    view.mask = node::SegmentAgainstBackground(view.image, *background, options.background).mask;
    view.silhouette_source = MaskOrigin::kBackgroundDifference;
  } else {
    throw InputError(fmt::format(
        "camera {} has no silhouette for still {}: provide its mask {} (0 background, 255 "
        "subject) or a photograph of the empty scene from the same camera, {}",
        camera.id, options.frame, files.mask.string(), files.background.string()));
  }
  if (cv::countNonZero(view.mask) == 0) {
    *problem = fmt::format("the silhouette ({}) is empty", ToString(view.silhouette_source));
    return std::nullopt;
  }
  return view;
}

}  // namespace

bool StillsFolderOptions::IsValid(std::string* reason) const {
  if (frame < 0) {
    *reason = "the still number must be >= 0";
    return false;
  }
  if (min_views < 2) {
    *reason = "stereo needs at least 2 views (min_views)";
    return false;
  }
  const std::string node_reason = background.node.Validate();
  if (!node_reason.empty()) {
    *reason = "background segmentation: " + node_reason;
    return false;
  }
  return true;
}

StereoViews LoadStillsFolder(const fs::path& dir, const fs::path& calibration,
                             const StillsFolderOptions& options) {
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("stills folder options: " + reason);
  if (!fs::is_directory(dir))
    throw InputError(fmt::format("{} is not a stills folder", dir.string()));
  const std::vector<CameraModel> cameras = LoadCalibration(calibration);
  StereoViews result;
  std::set<std::string> known;
  for (const CameraModel& camera : cameras) {
    known.insert(camera.id);
    std::string problem;
    std::optional<StereoView> view = LoadView(dir, camera, options, &problem);
    if (!view) {
      result.warnings.push_back(fmt::format("{}: {}; left out", camera.id, problem));
      continue;
    }
    if (view->nonbinary_mask_pixels > 0) {
      result.warnings.push_back(
          fmt::format("{}: {} mask pixels neither 0 nor 255, thresholded at 128", camera.id,
                      view->nonbinary_mask_pixels));
    }
    result.views.push_back(options.undistort ? UndistortView(*view) : std::move(*view));
  }
  for (const std::string& id : FoldersWithStills(dir)) {
    if (!known.contains(id)) {
      result.warnings.push_back(
          fmt::format("{}: stills but no camera in {}; left out", id, calibration.string()));
    }
  }
  if (static_cast<int>(result.views.size()) < options.min_views) {
    std::string why;
    for (const std::string& warning : result.warnings)
      why += "\n  " + warning;
    throw InputError(fmt::format("{}: {} usable camera(s), stereo needs at least {}{}",
                                 dir.string(), result.views.size(), options.min_views, why));
  }
  return result;
}

fs::path WriteStillsFolder(const fs::path& dir, const StereoViews& views, int frame) {
  for (const StereoView& view : views.views) {
    const CameraFiles files = FilesOf(dir, view.camera.id, frame);
    for (const fs::path& folder : {files.still.parent_path(), files.mask.parent_path()}) {
      std::error_code error;
      fs::create_directories(folder, error);
      if (error)
        throw InputError(fmt::format("cannot create {}: {}", folder.string(), error.message()));
    }
    WritePngFast(files.still, view.image);
    WritePngFast(files.mask, view.mask);
  }
  const fs::path calibration = dir / "calibration.yaml";
  SaveCalibration(calibration, views.Cameras());
  return calibration;
}

}  // namespace silnet::aggregator
