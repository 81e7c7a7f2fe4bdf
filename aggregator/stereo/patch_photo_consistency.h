#pragma once
// Photo-consistency of small oriented patches in space (thesis 7.3.2 and 7.4.1), the measure
// the adaptive stereo samples on the faces of its tetrahedra instead of voting in a lattice.
//
// A patch at point X with normal n is seen by the best `cameras` views whose direction from X
// makes at most `max_angle_deg` with n and whose silhouette holds X. It is mu x mu points
// spaced `step` on two directions perpendicular to n. (The thesis tests crossing faces with
// mu points on a line, the patch's intersection with the face, for speed; on our stills such
// lines, at their best of 14 orientations, score above 0.97 at 2-8 footprints from the surface,
// far too often to tell where it is: docs/PERFORMANCE.md.) The patch is projected into each chosen
// view (the projection linearised at X, exact to far below a pixel over a patch a few pixels wide),
// sampled bilinearly in grey, and every pair of views compared by normalised cross-correlation;
// each view's score is the mean of its best max(cameras / 2, 3) correlations with the others (a
// view may be occluded or see the point badly), and the patch's score is its best view's. A point's
// score in the crossing test is its best over the 14 canonical orientations (the six axis
// directions and the eight cube diagonals).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// Settings of the patch measure.
struct PatchOptions {
  int mu = 7;                 // points per patch side, odd, >= 3
  int cameras = 4;            // best views by angle per patch, >= 2
  int min_views = 3;          // fewer views with texture: the patch is not scored, >= 2
  double max_angle_deg = 60;  // largest angle between the patch normal and a view's direction
  double min_std = 2.0;       // a view's patch samples with less spread (0..255) have no texture

  // True if the options make sense; otherwise false with a reason.
  bool IsValid(std::string* reason) const;
};

// The 14 canonical patch orientations (unit vectors): the six axis directions, then the eight
// cube diagonals.
const std::array<Eigen::Vector3d, 14>& CanonicalOrientations();

// The score of one patch and what it was scored on.
struct PatchScore {
  float score = -1.0f;     // in [-1, 1]; -1 when fewer than min_views views could score it
  int views = 0;           // views that took part
  uint64_t view_mask = 0;  // bit v set if view v (< 64) took part
};

// Scores patches against calibrated, undistorted views (their images converted once).
class PatchScorer {
 public:
  // The views must outlive the scorer. Options must be valid (CheckError otherwise).
  PatchScorer(const std::vector<StereoView>& views, const PatchOptions& options);

  // True if X projects inside every view's image and silhouette that sees it in its image:
  // the point may be inside the visual hull.
  bool InsideSilhouettes(const Eigen::Vector3d& x) const;

  // The best plane patch at X over the canonical orientations (the patch perpendicular to
  // each), its index in `orientation` if given. With `prefilter` above -1 every orientation is
  // first scored on every other point (a quarter of the work): those below `prefilter` are
  // not scored in full, and of the others only the `full_orientations` best. -1 or less
  // scores every orientation in full.
  PatchScore BestPlane(const Eigen::Vector3d& x, double step, double prefilter = -1,
                       int* orientation = nullptr, int full_orientations = 14) const;
  // The plane patch at X spanned by unit directions u and v, normal `normal` (facing the views
  // that may score it).
  PatchScore Plane(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                   const Eigen::Vector3d& u, const Eigen::Vector3d& v, double step) const;
  // The better of the plane patches at X facing `normal` and facing -normal (as Plane, X
  // projected once). A side whose patch of every other point scores below `prefilter` (a
  // quarter of the work) keeps that score; -1 or less scores both sides in full.
  PatchScore PlaneEitherSide(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                             const Eigen::Vector3d& u, const Eigen::Vector3d& v, double step,
                             double prefilter = -1) const;

  // The scores of the patch at X (as Plane, but bent to a sphere of curvature `curvature`,
  // 1/metres, positive when it bulges towards the normal) moved along its normal to
  // X + d * normal for each d in `shifts` (metres, a few footprints at most: the projection
  // stays linearised at X), all in the views chosen at X, so the scores differ by the patch's
  // place only. (A plane patch on a curved surface scores best where it cuts the surface,
  // r^2 / 4R inside it: over a thin limb that is a footprint.)
  std::vector<float> AlongNormal(const Eigen::Vector3d& x, const Eigen::Vector3d& normal,
                                 const Eigen::Vector3d& u, const Eigen::Vector3d& v, double step,
                                 double curvature, const std::vector<double>& shifts) const;

  const PatchOptions& options() const { return options_; }

 private:
  struct View {
    Eigen::Matrix<double, 3, 4> projection;
    Eigen::Vector3d centre;
    cv::Mat grey;  // CV_32FC1
    const cv::Mat* mask = nullptr;
    int width = 0, height = 0;
  };
  // Views that may score a patch with `normal` at the point last projected (this thread's
  // scratch), best angle first, at most options.cameras.
  void ChooseViews(const Eigen::Vector3d& normal, std::vector<int>* chosen) const;
  // The points of a patch around the point last projected (defined in the .cc).
  struct PatchPoints;
  // Scores the patch's points in the chosen views.
  PatchScore Score(const PatchPoints& points, const std::vector<int>& chosen) const;
  // Scores every `stride`-th point of the mu x mu patch spanned by u and v around that point
  // in the views last chosen (this thread's scratch).
  PatchScore ScoreSpanned(const Eigen::Vector3d& u, const Eigen::Vector3d& v, double step,
                          int stride) const;

  std::vector<View> views_;
  PatchOptions options_;
};

}  // namespace silnet::aggregator
