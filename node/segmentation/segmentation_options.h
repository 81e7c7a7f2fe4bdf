#pragma once
// Settings of the node's background segmentation (thesis appendix B-1), with defaults that
// suit a static camera indoors, validation with readable reasons, and setting by name (for
// the config file and the aggregator's set-parameter command).

#include <map>
#include <string>

namespace silnet::node {

// Which background model segments colour frames.
enum class SegmentationMethod {
  kMedian,     // median bootstrap + per-pixel Gaussian, gain-compensated, with shadow test
  kMog2,       // OpenCV's Gaussian mixture (MOG2) with its shadow detection
  kKnn,        // OpenCV's k-nearest-neighbour model with its shadow detection
  kMaskInput,  // frames already are silhouettes: threshold them
};

// Parses "median", "mog2", "knn", "mask"; throws InputError otherwise.
SegmentationMethod ParseSegmentationMethod(const std::string& name);
std::string ToString(SegmentationMethod method);

// All settings; each has a default and a one-line meaning.
struct SegmentationOptions {
  SegmentationMethod method = SegmentationMethod::kMedian;
  // Median model: the background is the per-pixel median of the last `median_samples`
  // frames sampled every `median_stride` frames (about 7 s at 30 fps), refreshed a few rows
  // per frame; the model is warming up until the first window is full.
  int median_samples = 15;
  int median_stride = 15;
  // Foreground when the colour distance exceeds `threshold_sigmas` noise deviations
  // (per-pixel, learned) and at least `min_difference` digital numbers.
  double threshold_sigmas = 4.5;
  double min_difference = 12.0;
  // Rate at which each pixel's noise variance follows its background observations.
  double learning_rate = 0.02;
  // Shadows: pixels darker by a ratio in [shadow_min_ratio, shadow_max_ratio] with the same
  // colour (chromatic distortion below shadow_chroma) and the background's texture (the
  // ratio varies by less than shadow_texture over a 5x5 window) are background.
  bool suppress_shadows = true;
  double shadow_min_ratio = 0.35;
  double shadow_max_ratio = 0.92;
  double shadow_chroma = 0.08;
  double shadow_texture = 0.025;
  // OpenCV models: history length and variance threshold.
  int history = 300;
  double opencv_threshold = 16.0;
  // Clean-up: morphological opening and closing radii (pixels, 0 = off), blobs smaller than
  // min_blob_area removed, holes smaller than max_hole_area filled.
  int open_radius = 1;
  int close_radius = 2;
  int min_blob_area = 120;
  int max_hole_area = 200;
  // Graph-cut refinement of the boundary in a band of `graph_cut_band` pixels (slow; off).
  bool graph_cut = false;
  int graph_cut_band = 4;
  // Mask input: pixels above this are foreground.
  int mask_threshold = 127;

  // A readable reason if a setting is out of range, empty if all are fine.
  std::string Validate() const;
  // Sets one setting from text ("threshold_sigmas" = "5"); returns false with a reason for
  // an unknown name or an unparsable value. Does not validate ranges (call Validate()).
  bool Set(const std::string& name, const std::string& value, std::string* error);
  // All settings as name -> text, for CameraInfo and logs.
  std::map<std::string, std::string> ToMap() const;
};

}  // namespace silnet::node
