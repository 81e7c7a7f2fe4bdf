#pragma once
// The exact polyhedral visual hull (thesis 4.2, in the spirit of EPVH): the intersection of
// the calibrated cameras' viewing cones over their silhouette contours (polygons with holes),
// as a closed triangle mesh whose vertices are the hull's own: viewing-edge ends (a contour
// vertex's ray meeting another cone) and triple points (three cone faces meeting).
//
// The hull's edges are traced once from its viewing edges and each face closed from them
// (viewing_edges.h, hull_edges.h, traced_hull_mesh.h). Where that mesh is empty or not closed,
// each cone face's region is computed on its own (cone_face_region.h); vertices are named by
// the planes that meet there, so neighbouring faces agree on them without tolerances. Each
// face is triangulated as the polygon it is (face_boundary_loops.h, loop_triangulation.h),
// without extra points, and the assembled mesh is checked to be closed and manifold. Where
// that fails, the hull is traced again from slightly perturbed contours (the exact
// coincidences of symmetric rigs), then computed face by face from them, and where that fails
// too, assembled from the plain faces' sweeps' trapezoids, whose cuts on an edge both faces
// of the edge share (4-5 times the triangles). Where faces decide a near-degenerate
// configuration differently, the gap they leave is filled in the cone plane its outline lies
// on (in_plane_gap_filler.h); a mesh that is still not closed is reported as a failure, and
// callers fall back to the voxel hull.
//
// Distortion is removed from contour points before building the cones (contour edges become
// straight in the undistorted image).

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/cone_plane_set.h"
#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/hulls/voxel_grid.h"
#include "shared/geometry/camera_model.h"
#include "shared/silhouette/silhouette_contour.h"

namespace silnet::aggregator {

// Counts describing the hull's structure.
struct PolyhedralHullStats {
  size_t cone_faces = 0;             // contour edges over all cameras
  size_t hull_faces = 0;             // cone faces with a part on the hull
  size_t viewing_edge_vertices = 0;  // a contour vertex's ray meeting another cone
  size_t triple_points = 0;          // three cone faces of three cameras meeting
  size_t edge_points = 0;            // cuts on cone-intersection edges from the sweeps
  // The faces were triangulated with the sweeps' cuts on their edges (and `edge_points` are
  // mesh vertices), not as polygons of the hull's own vertices: a near-degenerate face made
  // the faster assembly fail.
  bool faces_with_cuts = false;
  // The hull of the plain contours did not close; this one is from the perturbed ones
  // (PolyhedralHullOptions::contour_perturbation_px), traced or face by face.
  bool contours_perturbed = false;
  // Gaps between faces that decided a near-degenerate configuration differently, filled in
  // the cone plane their outline lies on (in_plane_gap_filler.h): how many, their area (square
  // metres) and the widest one's mean width (metres).
  size_t gaps_filled = 0;
  double gap_area = 0;
  double widest_gap = 0;
  // Cameras that repeated another's viewpoint (coincident_cameras.h), their silhouettes
  // intersected into that camera's.
  size_t merged_cameras = 0;
  // The mesh came from the edges traced from the viewing edges (PolyhedralHullOptions::
  // trace_edges), not from the face-by-face sweeps.
  bool traced_edges = false;
};

// Where the hull's vertices come from (PolyhedralHullOptions::keep_provenance): the cone
// faces, each a contour edge of one view, and per mesh vertex the faces it lies on. A
// viewing-edge end lies on two consecutive faces of one view (the ray of the contour vertex
// between them) and one of another; a triple point on faces of three views. A mesh edge lies on
// the faces its two vertices share: two consecutive faces of one view make it a viewing edge,
// faces of two views a cone-intersection edge.
struct HullProvenance {
  std::vector<ConePlane> planes;  // every cone face; ConePlane::view indexes `view_cameras`
  std::vector<int> view_cameras;  // per view, the index of its camera in the caller's list
  std::vector<std::vector<int>> vertex_planes;  // per mesh vertex, its faces (sorted)
};

// The hull, or why there is none.
struct PolyhedralHullResult {
  bool success = false;
  std::string reason;  // when !success
  TriangleMesh mesh;   // closed, oriented, manifold when success
  PolyhedralHullStats stats;
  HullProvenance provenance;  // filled on success when asked for
};

// Settings of the computation.
struct PolyhedralHullOptions {
  double contour_tolerance_px = 0.6;  // Douglas-Peucker tolerance of the contours from masks
  // The mask outlines are smoothed along the ring this often before simplifying (fewer cone
  // faces for the same tolerance) and placed this far outside the boundary pixel centres
  // (slightly beyond the pixel edges, so the simplified outline still covers them).
  int contour_smoothing_passes = 1;
  double contour_offset_px = 0.6;
  // Simplify conservatively (covering_contour.h) instead: the silhouette's boundary pixel
  // centres lie at least `contour_cover_margin_px` inside the contour edges, so with true
  // cameras the hull misses almost no pixel; outline points `contour_cover_offset_px`
  // outside the centres. About 3.3 times the cone faces and time of the default contours,
  // hence off by default (docs/PERFORMANCE.md).
  bool contour_cover_pixel_centres = false;
  double contour_cover_offset_px = 0.4;
  double contour_cover_margin_px = 0.1;
  double contour_cover_background_slack_px = 0.15;  // see CoveringOptions
  double bounds_padding = 0.05;  // viewing-cone bounds are grown by this fraction per side
  // Where neither the traced edges nor the faces' polygons of the plain contours close, the
  // hull is traced and then computed face by face again from contour points moved by fixed
  // pseudo-random offsets up to this (pixels per coordinate; 0: not tried), before the
  // assembly with the cuts: that breaks the exact coincidences of symmetric rigs
  // (ConePlaneSet). Exactly symmetric rings of 6-24 cameras around a sphere did not close in
  // 25 of 40 configurations without it; all do with it, from their traced edges. The hull
  // moves by as little. Only a retry: on data the plain contours close, perturbed ones need
  // more gaps filled (where coincidences the faces agree on become near-coincidences they may
  // not).
  double contour_perturbation_px = 1e-3;
  // Threads for the contours, the cone planes' indexes, the cone faces and the faces'
  // polygons (0 = every core); the mesh is built in plane order and is the same for any count.
  // Callers that build several hulls at once (a sequence of frames) keep 1.
  int threads = 1;
  // Faces as polygons of the hull's own vertices; false: straight to the assembly with the
  // sweeps' cuts that the hull otherwise falls back to (for tests and comparisons).
  bool faces_as_polygons = true;
  // The hull's edges traced once from its viewing edges and its faces closed from them
  // (viewing_edges.h, hull_edges.h, traced_hull_mesh.h: 1.3-3x faster on the real datasets),
  // with the face-by-face sweeps below only where that mesh is empty or not closed; false:
  // the sweeps only (for tests and comparisons).
  bool trace_edges = true;
  // A silhouette the image border cuts continues beyond the frame: > 0 extends such masks by
  // this fraction of the image's larger side (the border pixels repeated outwards, the
  // camera's principal point moved with them) instead of refusing them, and refuses a hull
  // that reaches the outer half of an extension (the subject leaves that view too far for
  // the other views to bound it). Cameras with lens distortion are refused as before. 0: such
  // silhouettes are refused (the stereo job keeps those views apart itself).
  double border_extension = 0;
  // Gaps that neighbouring faces leave are filled (PolyhedralHullStats::gaps_filled) up to
  // this mean width, as a fraction of the hull's diagonal; a wider one means a face's region
  // was lost, not a near-degenerate decision: the assembly falls back to the cuts, and the
  // hull is refused if that leaves one too.
  double widest_gap_fraction = 1e-3;
  // Also return the hull's provenance (PolyhedralHullResult::provenance).
  bool keep_provenance = false;
};

// True if any pixel of the outermost rows or columns of `mask` is silhouette: the subject
// may continue outside the image, so the silhouette does not bound it.
bool TouchesBorder(const cv::Mat& mask);

// Builds the hull from one silhouette outline per camera (pixels of the camera's image, as
// ExtractContours gives them) inside `bounds`, which must contain the hull and lie in front
// of every camera. Fails as data (never throws) on empty silhouettes, silhouettes touching
// the image border (the subject may continue outside it), or a mesh that is not closed.
// Of `options`, the threads (the mesh does not depend on them), the contour perturbation and
// the assembly are used.
PolyhedralHullResult ComputePolyhedralHull(const std::vector<CameraModel>& cameras,
                                           const std::vector<SilhouetteContours>& contours,
                                           const WorldBox& bounds,
                                           const PolyhedralHullOptions& options = {});

// The same from CV_8UC1 masks (non-zero = silhouette), with bounds from the viewing cones.
PolyhedralHullResult ComputePolyhedralHull(const std::vector<CameraModel>& cameras,
                                           const std::vector<cv::Mat>& masks,
                                           const PolyhedralHullOptions& options = {});

}  // namespace silnet::aggregator
