#pragma once
// Holes of a silhouette against a background photograph that are the subject itself, where
// its colour came within the difference threshold of the background behind it ("camouflage":
// a dark patch of a statue in front of a dark wall). Left as holes, they become tunnels
// through the model under exact silhouette constraints (the statue of the main job: 8.9 ->
// 2.2 footprints of accuracy once one view's two patches were filled). A true hole (the gap
// between an arm and the body) shows the background: the photo inside it follows the
// background's texture (possibly darkened by a shadow) and differs from it by little more than
// noise. A camouflaged patch shows the subject's own texture: the photo's correlation with the
// background is low, and the difference, though under the threshold, well above the noise.
// A hole partly in a shadow the shadow test let pass (differences well above the threshold)
// shows the background too: the subject's shadow falls on the scene, not on the subject.

#include <opencv2/core/mat.hpp>

namespace silnet::node {

// When a hole is the subject.
struct CamouflageOptions {
  // Normalised cross-correlation of photo and background (grey) over the hole below this.
  double max_correlation = 0.3;
  // RMS colour distance over the hole above this many times the typical (median) distance of
  // the background pixels outside the silhouette (the noise between the two photographs).
  double min_difference_over_noise = 1.5;
  // A hole with a larger share of pixels differing by more than twice `threshold` (shadows the
  // shadow test let pass) is background.
  double max_shadow_share = 0.05;
  double threshold = 12.0;  // the segmentation's colour distance threshold (digital numbers)
  int min_area = 16;        // smaller holes are left to the clean-up (max_hole_area)
  // Bays are tested too: the background pixels next to the silhouette that closing it with a
  // disc of this radius (a fraction of the image diagonal) would cover; 0: holes only.
  double bay_radius_fraction = 0.01;
};

// Fills the holes of `mask` (CV_8UC1 0/255, 255 silhouette; background regions that do not
// reach the image border) and its bays (notches in its outline) that the photo `still` shows
// as the subject against `background` (CV_8UC3, the mask's size). Returns how many were
// filled.
int FillCamouflagedHoles(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                         const CamouflageOptions& options = {});

}  // namespace silnet::node
