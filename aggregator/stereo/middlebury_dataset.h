#pragma once
// Loaders for the Middlebury multi-view stereo rings (Seitz et al., CVPR 2006) in the shared
// data folder (its README.md): `<name>_par.txt` gives per image K, R, t with P = K [R | t]
// (pixel origin top-left, integer = pixel centre as in silnet), images are 640x480 PNGs of
// a matte object on black, and there are no masks.
//
// Silhouettes by thresholding the dark background (ThresholdDarkBackground): a pixel is
// subject when its brightest channel exceeds `threshold`, or when it exceeds
// `coloured_threshold` with a saturation above `min_saturation` (coloured object in shadow
// against a neutral backdrop). Then the node's clean-up (node/segmentation/mask_cleanup.h)
// opens and closes the mask (removing sensor specks, bridging the cracks that dark shadows
// leave on the object), components smaller than `min_component_fraction` of the largest are
// dropped (stray lit folds of the backdrop cloth), and holes up to `max_hole_area` pixels are
// filled, as are larger holes brighter than the backdrop around the subject (their median
// above its 95th percentile: the dino's shadowed crevices, 400-1200 px with medians 22-36
// against a backdrop's 14-21; the temple's through-hole, medians 1-23 against 38-47, and a
// dark gap in the dino's view 15, 16 against 17, stay). Settings per ring (MiddleburyPreset,
// measured in tests/aggregator/stereo, figures in docs/PERFORMANCE.md): the dino's backdrop is
// black (brightest channel <= 19) and its shadows neutral, so threshold 40; the temple's backdrop
// cloth reaches 85 where lit and its shadowed stone is dark but yellow, so threshold 90 or
// brightest > 30 with saturation > 0.45 (the cloth's is 0.1-0.4).

#include <filesystem>
#include <optional>
#include <string>

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// Settings of the silhouettes.
struct DarkBackgroundOptions {
  int threshold = 48;  // subject where max(B, G, R) > threshold (digital numbers)
  // ... or where max(B, G, R) > coloured_threshold and the saturation (max - min) / max >
  // min_saturation: coloured object in shadow against a neutral backdrop (> 1 = off).
  int coloured_threshold = 30;
  double min_saturation = 2.0;
  int open_radius = 1;      // morphological opening radius (pixels, 0 = off)
  int close_radius = 3;     // morphological closing radius (pixels, 0 = off)
  int max_hole_area = 400;  // background holes up to this many pixels are filled
  // ... and larger ones whose median brightness exceeds this percentile of the background
  // around the subject (shadow pockets; the backdrop seen through a gap is darker); > 1 = off.
  double shadow_pocket_percentile = 0.95;
  double min_component_fraction = 0.02;  // smaller components (of the largest's area) dropped

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// The silhouette (CV_8UC1, 0/255) of a CV_8UC3 photograph of an object on black.
cv::Mat ThresholdDarkBackground(const cv::Mat& image, const DarkBackgroundOptions& options = {});

// The settings measured for a ring, by its file prefix: "dinoSR"/"dinoR"/"dino" (any name
// starting "dino"), "temple..."; others get the defaults (the authors' threshold 0.19).
DarkBackgroundOptions MiddleburyPreset(const std::string& prefix);

// Loads a Middlebury folder (the one `*_par.txt` file in it and the images it names) as
// stereo views named by the image stems ("dinoSR0001"), silhouettes by threshold with
// `options`, or MiddleburyPreset of the par file's prefix when unset. Images the authors left
// out of `*_good_silhouette_images.txt`, when that file exists, are kept and named in a
// warning. Rotations are replaced by the nearest rotation matrix (the dino's are orthonormal
// to 1.5e-6 only). Throws InputError for a missing or malformed file, or invalid options.
StereoViews LoadMiddlebury(const std::filesystem::path& folder,
                           const std::optional<DarkBackgroundOptions>& options = std::nullopt);

// Writes a Middlebury folder as a stills folder (stills_folder.h) at `out`, frame 0, with
// the thresholded silhouettes as masks; returns the calibration's path. Throws InputError
// as LoadMiddlebury and WriteStillsFolder do.
std::filesystem::path WriteMiddleburyAsStillsFolder(
    const std::filesystem::path& folder, const std::filesystem::path& out,
    const std::optional<DarkBackgroundOptions>& options = std::nullopt);

}  // namespace silnet::aggregator
