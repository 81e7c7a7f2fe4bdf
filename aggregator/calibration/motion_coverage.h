#pragma once
// How much a camera's silhouettes moved during a capture (thesis 2.3: the epipolar geometry
// is constrained only by outer tangents that touch the silhouettes at many places and from
// many directions): the share of the image the silhouettes swept, the share of tangent
// directions in which their extremes moved, and the frames in which they moved at all. Too
// little of any means the calibration cannot be trusted, and the user is told what to do.

#include <opencv2/core/mat.hpp>
#include <string>

#include "aggregator/pairwise/silhouette_sequence.h"

namespace silnet::aggregator {

// Thresholds of "enough motion".
struct MotionCoverageOptions {
  int grid_columns = 32;  // the image is counted in cells of (larger side / grid_columns) px
  int directions = 16;    // tangent directions, evenly around the circle
  double direction_spread = 0.02;  // a direction moved: its extreme's spread over the frames,
                                   // as a share of the image diagonal, at least this
  double frame_motion_px = 1.0;    // a frame moved: some extreme moved this far since the last
  double min_image_share = 0.12;
  double min_direction_share = 0.5;
  size_t min_moving_frames = 30;
};

// The motion figures of one camera.
struct MotionCoverage {
  std::string camera_id;
  size_t frames = 0;             // frames held
  size_t usable_frames = 0;      // with a usable silhouette
  size_t moving_frames = 0;      // usable frames whose silhouette moved since the last one
  double image_share = 0.0;      // grid cells a silhouette covered at least once / all cells
  double direction_share = 0.0;  // tangent directions whose extremes moved / all
  bool sufficient = false;
  std::string advice;  // what is lacking and what to do; empty when sufficient
  cv::Mat counts;      // CV_32SC1 grid: frames whose silhouette covered each cell

  // One line: "swept 23 % of the image, moved in 16 of 16 directions, 250 of 272 frames".
  std::string Describe() const;
};

// Measures the motion of `sequence`.
MotionCoverage MeasureMotionCoverage(const SilhouetteSequence& sequence,
                                     const MotionCoverageOptions& options = {});

// A picture of the coverage (BGR, `width` px wide): cells shaded by how often a silhouette
// covered them (black never), with the camera id and the figures written on it.
cv::Mat DrawMotionCoverage(const MotionCoverage& coverage, int width = 320);

}  // namespace silnet::aggregator
