#include "aggregator/hulls/polyhedral_hull.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "aggregator/hulls/coincident_cameras.h"
#include "aggregator/hulls/cone_face_region.h"
#include "aggregator/hulls/face_assembly.h"
#include "aggregator/hulls/hull_edges.h"
#include "aggregator/hulls/in_plane_gap_filler.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/traced_hull_mesh.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/viewing_edges.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Vertices closer than this fraction of the bounds' diagonal are one point.
constexpr double kWeldTolerance = 1e-9;

// The pixels a silhouette's outline encloses (its pixel centres lie inside the outline), as
// a rectangle clipped to the image; empty for an empty outline.
cv::Rect PixelRect(const SilhouetteContours& contours, const cv::Size& image) {
  float x0 = std::numeric_limits<float>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const ContourPolygon& polygon : contours.polygons) {
    for (const Eigen::Vector2f& x : polygon.outer) {
      x0 = std::min(x0, x.x());
      y0 = std::min(y0, x.y());
      x1 = std::max(x1, x.x());
      y1 = std::max(y1, x.y());
    }
  }
  if (!(x1 >= x0)) return {};
  const cv::Rect enclosing(
      cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
      cv::Point(static_cast<int>(std::ceil(x1)) + 1, static_cast<int>(std::ceil(y1)) + 1));
  return enclosing & cv::Rect(cv::Point(0, 0), image);
}

// The first camera whose silhouette touches its image border, or -1.
int FirstCameraTouchingBorder(const std::vector<CameraModel>& cameras,
                              const std::vector<SilhouetteContours>& contours) {
  // Outline points of a border pixel lie 0.25 to 0.5 px outside the image's pixel centres.
  for (size_t v = 0; v < cameras.size(); ++v) {
    const float right = static_cast<float>(cameras[v].width) - 1.25f;
    const float bottom = static_cast<float>(cameras[v].height) - 1.25f;
    for (const ContourPolygon& polygon : contours[v].polygons) {
      for (const Eigen::Vector2f& x : polygon.outer) {
        if (x.x() < 0.25f || x.y() < 0.25f || x.x() > right || x.y() > bottom)
          return static_cast<int>(v);
      }
    }
  }
  return -1;
}

// Extends the mask of `camera` by `margin` pixels on every side, its border pixels repeated
// outwards and the new outermost ring left empty (so the extension ends inside the larger
// image), and moves the camera's principal point and size with it.
void ExtendBeyondBorder(int margin, CameraModel& camera, cv::Mat& mask) {
  cv::Mat extended;
  cv::copyMakeBorder(mask, extended, margin, margin, margin, margin, cv::BORDER_REPLICATE);
  extended.row(0).setTo(0);
  extended.row(extended.rows - 1).setTo(0);
  extended.col(0).setTo(0);
  extended.col(extended.cols - 1).setTo(0);
  mask = extended;
  camera.K(0, 2) += margin;
  camera.K(1, 2) += margin;
  camera.width += 2 * margin;
  camera.height += 2 * margin;
}

// The first extended camera (margin > 0) in whose outer half of the extension a hull vertex
// projects, or -1.
int LeavesExtension(const std::vector<CameraModel>& cameras, const std::vector<int>& margins,
                    const TriangleMesh& mesh) {
  for (size_t v = 0; v < cameras.size(); ++v) {
    if (margins[v] == 0) continue;
    const Matrix34d P = cameras[v].ProjectionMatrix();
    const double limit = 0.5 * margins[v];
    const double right = cameras[v].width - limit, bottom = cameras[v].height - limit;
    for (const Eigen::Vector3f& x : mesh.vertices) {
      const Eigen::Vector2d pixel = (P * x.cast<double>().homogeneous()).hnormalized();
      if (pixel.x() < limit || pixel.y() < limit || pixel.x() > right || pixel.y() > bottom)
        return static_cast<int>(v);
    }
  }
  return -1;
}

// Every cone face's region, in parallel; false with the first failing face's reason.
bool ComputeFaceRegions(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                        const WorldBox& bounds, int threads, std::vector<FaceRegion>* regions,
                        std::string* reason) {
  regions->assign(set.Planes().size(), FaceRegion{});
  ParallelFor(regions->size(), threads, [&](size_t p) {
    (*regions)[p] = ComputeFaceRegion(cameras, set, static_cast<int>(p), bounds);
  });
  for (const FaceRegion& region : *regions) {
    if (!region.success) {
      *reason = region.reason;
      return false;
    }
  }
  return true;
}

// An assembled mesh and whether it is a closed manifold.
struct HullAssembly {
  PolyhedralHullResult result;  // mesh and stats; success not yet set
  bool closed = false;
};

// The faces' regions assembled in plane order: each face as the polygon it is or, with
// `with_cuts`, as its trapezoids with the cuts the neighbouring faces made on their common
// edges. Gaps that faces deciding a near-degenerate configuration differently leave are
// filled up to options.widest_gap_fraction.
HullAssembly AssembleHull(const ConePlaneSet& set, const std::vector<FaceRegion>& regions,
                          const WorldBox& bounds, const PolyhedralHullOptions& options,
                          bool with_cuts) {
  HullAssembly assembly;
  PolyhedralHullResult& result = assembly.result;
  FaceAssembly faces =
      AssembleFaces(set, regions, with_cuts, options.threads,
                    kWeldTolerance * bounds.diagonal().norm(), options.keep_provenance);
  if (!faces.success) {
    result.reason = "a face's boundary is not closed loops";
    return assembly;
  }
  const bool open = faces.Open();
  result.mesh = std::move(faces.mesh);
  result.stats = faces.stats;
  result.stats.cone_faces = set.Planes().size();
  result.stats.faces_with_cuts = with_cuts;
  MeshCheck check = faces.check;
  if (open || options.keep_provenance) {
    result.provenance.vertex_planes = std::move(faces.vertex_planes);
    if (options.keep_provenance) {
      result.provenance.planes = set.Planes();
      result.provenance.view_cameras.resize(set.Views());
      for (size_t v = 0; v < set.Views(); ++v)
        result.provenance.view_cameras[v] = static_cast<int>(v);
    }
  }
  if (open) {
    const GapFilling filling = FillInPlaneGaps(result.provenance.vertex_planes, result.mesh);
    result.stats.gaps_filled = filling.filled;
    result.stats.gap_area = filling.area;
    result.stats.widest_gap = filling.widest;
    Eigen::AlignedBox3f extent;
    for (const Eigen::Vector3f& x : result.mesh.vertices)
      extent.extend(x);
    const double share = filling.widest / extent.diagonal().norm();
    if (share > options.widest_gap_fraction) {
      result.reason = fmt::format(
          "the polyhedral mesh is not a closed manifold: neighbouring cone faces leave a gap "
          "{:.3g} of the hull's size wide (gaps up to {:.3g} are filled)",
          share, options.widest_gap_fraction);
      return assembly;
    }
    check = CheckClosedManifold(result.mesh);
  }
  if (!options.keep_provenance) result.provenance = HullProvenance{};
  assembly.closed = check.closed_manifold;
  if (!check.closed_manifold)
    result.reason = fmt::format("the polyhedral mesh is not a closed manifold: {}", check.reason);
  return assembly;
}

// The hull from its edges traced once from the viewing edges; `closed` false where the mesh
// is empty (no viewing edge: the sweeps decide) or not a closed manifold.
HullAssembly TracedHull(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                        const WorldBox& bounds, const PolyhedralHullOptions& options) {
  HullAssembly assembly;
  const std::vector<ViewingEdge> viewing =
      ComputeViewingEdges(cameras, set, bounds, options.threads);
  const HullEdgeGraph graph = TraceHullEdges(cameras, set, bounds, viewing, options.threads);
  TracedHullMesh traced = AssembleTracedHull(set, graph);
  if (!traced.success || graph.open_ends > 0 || traced.mesh.triangles.empty()) return assembly;
  if (!CheckClosedManifold(traced.mesh).closed_manifold) return assembly;
  PolyhedralHullResult& result = assembly.result;
  result.mesh = std::move(traced.mesh);
  result.stats.cone_faces = set.Planes().size();
  result.stats.hull_faces = traced.faces;
  result.stats.viewing_edge_vertices = 2 * viewing.size();
  result.stats.triple_points = graph.vertices.size() - 2 * viewing.size();
  result.stats.traced_edges = true;
  if (options.keep_provenance) {
    result.provenance.planes = set.Planes();
    result.provenance.view_cameras.resize(set.Views());
    for (size_t v = 0; v < set.Views(); ++v)
      result.provenance.view_cameras[v] = static_cast<int>(v);
    for (const HullEdgeVertex& vertex : graph.vertices)
      result.provenance.vertex_planes.emplace_back(vertex.planes.begin(), vertex.planes.end());
  }
  assembly.closed = true;
  return assembly;
}

// The hull from the contours perturbed by options.contour_perturbation_px: traced edges first
// (where `trace`), then face by face; `closed` false where neither closes.
HullAssembly PerturbedHull(const std::vector<CameraModel>& cameras,
                           const std::vector<SilhouetteContours>& contours, const WorldBox& bounds,
                           const PolyhedralHullOptions& options, bool trace) {
  const ConePlaneSet perturbed(cameras, contours, bounds, options.contour_perturbation_px,
                               options.threads);
  HullAssembly assembly;
  if (trace) assembly = TracedHull(cameras, perturbed, bounds, options);
  std::vector<FaceRegion> regions;
  std::string reason;
  if (!assembly.closed &&
      ComputeFaceRegions(cameras, perturbed, bounds, options.threads, &regions, &reason))
    assembly = AssembleHull(perturbed, regions, bounds, options, false);
  assembly.result.stats.contours_perturbed = assembly.closed;
  return assembly;
}

// `result` with success set: a non-empty closed mesh.
PolyhedralHullResult Finished(PolyhedralHullResult result) {
  if (result.mesh.triangles.empty()) {
    result.reason = "the viewing cones do not intersect: the hull is empty";
  } else if (result.reason.empty()) {
    result.success = true;
  }
  return result;
}

}  // namespace

bool TouchesBorder(const cv::Mat& mask) {
  return cv::countNonZero(mask.row(0)) > 0 || cv::countNonZero(mask.row(mask.rows - 1)) > 0 ||
         cv::countNonZero(mask.col(0)) > 0 || cv::countNonZero(mask.col(mask.cols - 1)) > 0;
}

PolyhedralHullResult ComputePolyhedralHull(const std::vector<CameraModel>& cameras,
                                           const std::vector<SilhouetteContours>& contours,
                                           const WorldBox& bounds,
                                           const PolyhedralHullOptions& options) {
  PolyhedralHullResult result;
  if (cameras.size() < 2 || contours.size() != cameras.size()) {
    result.reason = fmt::format(
        "need one contour set per camera and at least two cameras ({} "
        "cameras, {} contour sets)",
        cameras.size(), contours.size());
    return result;
  }
  for (size_t v = 0; v < cameras.size(); ++v) {
    if (contours[v].polygons.empty()) {
      result.reason = fmt::format("the silhouette of {} is empty", cameras[v].id);
      return result;
    }
  }
  const CoincidentCameras coincident = FindCoincidentCameras(cameras);
  if (!coincident.conflict.empty()) {
    result.reason = coincident.conflict;
    return result;
  }
  for (size_t v = 0; v < cameras.size(); ++v) {
    if (coincident.same_as[v] == static_cast<int>(v)) continue;
    result.reason = fmt::format(
        "cameras {} and {} repeat one viewpoint: the exact hull needs distinct viewpoints (the "
        "masks overload intersects their silhouettes)",
        cameras[static_cast<size_t>(coincident.same_as[v])].id, cameras[v].id);
    return result;
  }
  if (const int v = FirstCameraTouchingBorder(cameras, contours); v >= 0) {
    result.reason = fmt::format("the silhouette of {} touches the image border",
                                cameras[static_cast<size_t>(v)].id);
    return result;
  }
  const ConePlaneSet set(cameras, contours, bounds, 0, options.threads);
  const bool trace = options.trace_edges && options.faces_as_polygons;
  if (trace) {
    HullAssembly traced = TracedHull(cameras, set, bounds, options);
    if (traced.closed) return Finished(std::move(traced.result));
  }
  std::vector<FaceRegion> regions;
  if (!ComputeFaceRegions(cameras, set, bounds, options.threads, &regions, &result.reason))
    return result;
  if (options.faces_as_polygons) {
    HullAssembly assembly = AssembleHull(set, regions, bounds, options, false);
    if (assembly.closed) return Finished(std::move(assembly.result));
    if (options.contour_perturbation_px > 0) {
      HullAssembly perturbed = PerturbedHull(cameras, contours, bounds, options, trace);
      if (perturbed.closed) return Finished(std::move(perturbed.result));
    }
  }
  return Finished(AssembleHull(set, regions, bounds, options, true).result);
}

PolyhedralHullResult ComputePolyhedralHull(const std::vector<CameraModel>& cameras,
                                           const std::vector<cv::Mat>& masks,
                                           const PolyhedralHullOptions& options) {
  PolyhedralHullResult result;
  if (masks.size() != cameras.size()) {
    result.reason = "need one mask per camera";
    return result;
  }
  ContourOptions contour_options;
  contour_options.tolerance_px = options.contour_tolerance_px;
  contour_options.smoothing_passes = options.contour_smoothing_passes;
  contour_options.boundary_offset_px = options.contour_cover_pixel_centres
                                           ? options.contour_cover_offset_px
                                           : options.contour_offset_px;
  contour_options.cover_pixel_centres = options.contour_cover_pixel_centres;
  contour_options.cover_margin_px = options.contour_cover_margin_px;
  contour_options.cover_background_slack_px = options.contour_cover_background_slack_px;
  for (size_t v = 0; v < masks.size(); ++v) {
    result.reason = MaskShapeProblem(cameras[v], masks[v]);
    if (!result.reason.empty()) return result;
  }
  // A camera that repeats another's viewpoint adds its silhouette to that camera's (the
  // intersection of the two) instead of a second, coincident cone.
  const CoincidentCameras coincident = FindCoincidentCameras(cameras);
  if (!coincident.conflict.empty()) {
    result.reason = coincident.conflict;
    return result;
  }
  std::vector<CameraModel> hull_cameras;
  std::vector<cv::Mat> hull_masks;
  std::vector<size_t> slot(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    const auto first = static_cast<size_t>(coincident.same_as[v]);
    if (first == v) {
      slot[v] = hull_cameras.size();
      hull_cameras.push_back(cameras[v]);
      hull_masks.push_back(masks[v]);
    } else {
      cv::Mat both;
      cv::bitwise_and(hull_masks[slot[first]], masks[v], both);
      hull_masks[slot[first]] = both;
    }
  }
  const size_t merged_cameras = cameras.size() - hull_cameras.size();
  // Silhouettes the image border cuts, extended beyond it where asked.
  const size_t views = hull_cameras.size();
  std::vector<int> margins(views, 0);
  for (size_t v = 0; v < views; ++v) {
    if (!(options.border_extension > 0) || hull_cameras[v].HasDistortion() ||
        !TouchesBorder(hull_masks[v])) {
      continue;
    }
    margins[v] = static_cast<int>(
        std::ceil(options.border_extension * std::max(hull_masks[v].cols, hull_masks[v].rows)));
    ExtendBeyondBorder(margins[v], hull_cameras[v], hull_masks[v]);
  }
  std::vector<SilhouetteContours> contours(views);
  std::vector<cv::Rect> rects(views);
  ParallelFor(views, options.threads, [&](size_t v) {
    contours[v] = ExtractContours(hull_masks[v], contour_options);
    rects[v] = PixelRect(contours[v], hull_masks[v].size());
  });
  const ViewingConeBounds bounds = ComputeViewingConeBounds(hull_cameras, rects);
  if (!bounds.success) {
    result.reason = bounds.reason;
    return result;
  }
  WorldBox box = bounds.box;
  const Eigen::Vector3d pad = options.bounds_padding * box.sizes();
  box.min() -= pad;
  box.max() += pad;
  result = ComputePolyhedralHull(hull_cameras, contours, box, options);
  result.stats.merged_cameras = merged_cameras;
  if (options.keep_provenance && result.success) {
    for (size_t v = 0; v < cameras.size(); ++v) {
      if (coincident.same_as[v] == static_cast<int>(v))
        result.provenance.view_cameras[slot[v]] = static_cast<int>(v);
    }
  }
  if (result.success) {
    if (const int v = LeavesExtension(hull_cameras, margins, result.mesh); v >= 0) {
      result = PolyhedralHullResult{};
      result.reason = fmt::format(
          "the silhouette of {} touches the image border and the hull reaches far beyond it",
          hull_cameras[static_cast<size_t>(v)].id);
    }
  } else {
    std::string extended;
    for (size_t v = 0; v < views; ++v) {
      if (margins[v] == 0) continue;
      if (!extended.empty()) extended += ", ";
      extended += hull_cameras[v].id;
    }
    if (!extended.empty()) {
      result.reason =
          fmt::format("{} (with the silhouettes of {} extended beyond the image border)",
                      result.reason, extended);
    }
  }
  return result;
}

}  // namespace silnet::aggregator
