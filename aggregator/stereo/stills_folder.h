#pragma once
// Loads a stills folder, the stereo job's input (DESIGN.md "Files"):
//   <dir>/<camera>/stills/%06d.png    colour photographs
//   <dir>/<camera>/masks/%06d.png     silhouettes, 0/255, same frame number
//   <dir>/<camera>/background.png     optional: the empty scene, for cameras without masks
// and a calibration YAML (shared/io/calibration_yaml.h). A camera is used when the
// calibration and the folder both have it.
//
// Problems with one camera are reported as warnings and the camera left out: a camera of
// the calibration without that still, a folder with stills but no camera in the calibration,
// an unreadable or corrupt PNG, an image or mask whose size differs from the calibration's,
// an empty silhouette. Mask pixels other than 0 and 255 are thresholded at 128 and counted
// (a warning and StereoView::nonbinary_mask_pixels). A camera without that mask file is
// segmented against its background.png (node/segmentation/background_difference.h); with neither,
// loading stops with an InputError naming the camera and the files to provide. Fewer than
// `min_views` usable cameras is an InputError listing the warnings.

#include <filesystem>
#include <string>

#include "aggregator/stereo/stereo_views.h"
#include "node/segmentation/background_difference.h"

namespace silnet::aggregator {

// Settings of the loader.
struct StillsFolderOptions {
  int frame = 0;          // the still taken: stills/%06d.png and masks/%06d.png
  bool undistort = true;  // pinhole views (undistort_view.h); false keeps the distortion
  int min_views = 2;      // fewer usable cameras is an error
  node::BackgroundDifferenceOptions background;  // segmentation of cameras without masks

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// Loads the usable views of `dir` with the cameras of `calibration`, in the calibration's
// camera order. Throws InputError for invalid options, an unreadable calibration, a camera
// with no silhouette source, or too few usable views.
StereoViews LoadStillsFolder(const std::filesystem::path& dir,
                             const std::filesystem::path& calibration,
                             const StillsFolderOptions& options = {});

// Writes `views` as a stills folder: images and masks as frame `frame` of the layout above
// and the cameras as `<dir>/calibration.yaml`, whose path is returned. Throws InputError if a
// file cannot be written.
std::filesystem::path WriteStillsFolder(const std::filesystem::path& dir, const StereoViews& views,
                                        int frame = 0);

}  // namespace silnet::aggregator
