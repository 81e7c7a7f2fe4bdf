#pragma once
// The 2-colouring of the exact visual hull's vertices (thesis 6.4-6.5), which the graph cut
// with exact silhouette constraints (6.6-6.7) sets its sources and sinks from. The rims of n
// views cut any closed surface into regions that can be 2-coloured (lemma 6.4.1: the colour
// is the parity of the views the surface faces); the hull's topology gives that colouring at
// its vertices without knowing the surface:
//   1. each viewing ray's true segment by the rim graph (rim_graph.h);
//   2. each cone strip repaired: where successive true segments share no face piece (a
//      T-junction), a connecting curve on the rest of the hull, the shortest path whose edges
//      project closest to the view's outline (eq. 6.1); its vertices are rim vertices;
//   3. per view, front (nearer end of a true segment) and back (farther end) labels flooded
//      over the mesh without crossing the repaired strip (its pieces between true segments,
//      the true segments and the curves); where both reach, a rim of the view runs hidden
//      behind another part of the subject, and the hull's own facing decides;
//   4. red where an even number of views see the vertex from the front, blue where odd, green
//      on a rim vertex of any view (and where a view's floods did not reach: the strips and
//      curves around it leave its side undecided).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// A hull vertex's colour.
enum class HullVertexColour : uint8_t { kRed, kBlue, kGreen };

// Settings of the colouring.
struct HullColouringOptions {
  double discontinuity_cost = 50;  // K of the rim graph (the thesis: 50)
  double curve_epsilon = 1e-3;     // e of eq. 6.1, added per edge of a connecting curve (px^2)
};

// What the colouring found.
struct HullColouringStats {
  size_t segments = 0;           // view-edge segments
  size_t false_segments = 0;     // segments not chosen as their ray's true one
  size_t connecting_curves = 0;  // strip repairs (rim discontinuities)
  size_t unconnected = 0;        // discontinuities no path on the hull joins
  size_t green_vertices = 0;     // rim vertices of some view, or unlabelled in one
  size_t unlabelled = 0;         // (vertex, view) pairs no flood reached, rim vertices aside
  // (vertex, view) pairs both sides reach: a rim of the view runs hidden (behind another part
  // of the subject) between them, which the hull does not show (thesis 6.4); the hull's own
  // facing labels them.
  size_t hidden_rim = 0;
};

// Per vertex its colour, and the per-view labels it came from.
struct HullColouring {
  std::vector<HullVertexColour> colours;
  // labels[view][vertex]: 1 front, 0 back, -1 rim vertex of the view or not reached; views as
  // in the provenance (HullProvenance::view_cameras).
  std::vector<std::vector<int8_t>> labels;
  HullColouringStats stats;
};

// How photo-consistent the most photo-consistent point of the segment a-b is, in [-1, 1].
using SegmentPhotoConsistency =
    std::function<double(const Eigen::Vector3d& a, const Eigen::Vector3d& b)>;

// Colours the vertices of `hull`, a closed exact hull with its `provenance`, built from
// `cameras` and `masks` (CV_8UC1, non-zero = silhouette; the caller's lists, which the
// provenance's view_cameras index).
HullColouring ColourHullVertices(const TriangleMesh& hull, const HullProvenance& provenance,
                                 const std::vector<CameraModel>& cameras,
                                 const std::vector<cv::Mat>& masks,
                                 const SegmentPhotoConsistency& photo_consistency,
                                 const HullColouringOptions& options = {});

}  // namespace silnet::aggregator
