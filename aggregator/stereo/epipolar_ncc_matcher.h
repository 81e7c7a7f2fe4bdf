#pragma once
// Two-view matching along epipolar lines (thesis 6.8.1): a reference pixel's mu x mu window
// is compared by normalised cross-correlation (NCC, thesis A.2) with windows centred on the
// projection of its viewing ray into a neighbour view, sampled at about one pixel steps over
// the depth range the visual hull allows. Unlike binocular stereo that keeps the best score,
// every local maximum of the NCC curve above a threshold is a match hypothesis, refined to
// sub-pixel position by a parabola through it and its two neighbours and turned into a depth
// on the reference ray (exact two-view triangulation, the refined point lying on the
// epipolar line). Image-space windows, axis-aligned in both images, as in the thesis (its
// turntable sequences did not need object-space patches).
//
// Windows in the neighbour are sampled bilinearly at sub-pixel centres: the samples follow
// the epipolar line exactly, whatever its direction, with no rectification (which would
// resample and shear both images for the 20-50 degree baselines of a ring).

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// Settings of the matching.
struct EpipolarNccOptions {
  int window = 7;        // mu: window side in pixels, odd, 3..31 (docs/PERFORMANCE.md)
  bool colour = false;   // NCC over the three BGR channels instead of grey
  double min_ncc = 0.8;  // local maxima scoring less are not matches
  double step_px = 1.0;  // largest spacing of the samples along the epipolar line, pixels
  double min_std = 2.0;  // windows whose standard deviation (0..255 levels) is less: no texture
  // A neighbour window with a smaller share of its pixels inside the neighbour's silhouette is
  // not scored (it partly shows background, which differs between views); its centre must be
  // inside the silhouette in any case. 1 = wholly inside: parts thinner than the window
  // (the statue's staff) get no matches, the hull alone places them.
  double min_window_in_silhouette = 1.0;
  int max_matches = 0;  // per pixel and neighbour: only the best this many maxima; 0 = all

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// A view's image prepared for window sampling.
struct NccImage {
  cv::Mat pixels;         // CV_32FC1 grey or CV_32FC3 BGR, levels 0..255
  int channels = 1;       // 1 or 3
  cv::Mat mask;           // CV_8UC1, non-zero inside the silhouette
  cv::Mat mask_integral;  // CV_32SC1, (rows + 1) x (cols + 1) counts of silhouette pixels

  // Converts the view's image (grey unless `colour`) and indexes its mask.
  static NccImage FromView(const StereoView& view, bool colour);
};

// The window of integer pixel (x, y) of `image` as window^2 * channels values, zero-mean and
// of unit norm, into `window` (resized). False if the window leaves the image or its standard
// deviation is below options.min_std.
bool ReferenceWindow(const NccImage& image, int x, int y, const EpipolarNccOptions& options,
                     std::vector<float>* window);

// NCC in [-1, 1] of a ReferenceWindow with the window of `image` centred at sub-pixel (u, v)
// (pixel centres at integers), bilinearly interpolated; NaN if that window leaves the image or
// has no texture (options.min_std).
float WindowNcc(const NccImage& image, const float* reference_window, double u, double v,
                const EpipolarNccOptions& options);

// A reference viewing ray X(d) = centre + d * direction as seen by a neighbour camera: the
// homogeneous pixel of X(d) is a + d * b (pinhole, no distortion). With direction = R^T K^-1
// (x, y, 1) of the reference camera, d is the point's depth (z) in the reference camera.
struct EpipolarRay {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();

  static EpipolarRay Of(const CameraModel& neighbour, const Eigen::Vector3d& centre,
                        const Eigen::Vector3d& direction);
  // Neighbour pixel of the ray's point at `depth`; only for points in front of the neighbour.
  Eigen::Vector2d PixelAt(double depth) const;
  // The depth whose point projects to `pixel`, a point on the epipolar line (triangulation).
  double DepthAt(const Eigen::Vector2d& pixel) const;
  // True if the point at `depth` is in front of the neighbour.
  bool InFront(double depth) const { return a.z() + depth * b.z() > 0.0; }
};

// One match hypothesis on a reference ray.
struct EpipolarMatch {
  double depth = 0.0;  // along the reference ray, as EpipolarRay
  float ncc = 0.0f;    // the NCC at the (integer-step) maximum
};

// Counters of ScanEpipolarSegment, added to.
struct EpipolarScanCounts {
  size_t samples = 0;  // positions along epipolar lines
  size_t scored = 0;   // of which had an NCC (window inside image and silhouette, textured)
  size_t maxima = 0;   // local maxima at or above min_ncc (before max_matches)
};

// Scans the neighbour's epipolar segment of depths [near, far] (both in front of the
// neighbour) at spacing <= options.step_px, with one extra sample beyond each end so that
// maxima at the ends are found, and appends every local maximum with NCC >= options.min_ncc,
// its depth refined by the parabola through the maximum and its two neighbours (max_matches
// is not applied here: see KeepBestMatches). `scores` is scratch space.
void ScanEpipolarSegment(const NccImage& neighbour, const float* reference_window,
                         const EpipolarRay& ray, double near, double far,
                         const EpipolarNccOptions& options, std::vector<float>* scores,
                         std::vector<EpipolarMatch>* matches, EpipolarScanCounts* counts);

// Keeps only the `count` highest-NCC matches of matches[first, end) (ties by depth), in
// depth order; nothing happens when count <= 0 or there are no more.
void KeepBestMatches(int count, size_t first, std::vector<EpipolarMatch>* matches);

}  // namespace silnet::aggregator
