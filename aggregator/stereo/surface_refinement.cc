#include "aggregator/stereo/surface_refinement.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <limits>

#include "aggregator/stereo/coverage_restore.h"
#include "aggregator/stereo/taubin_smoothing.h"
#include "aggregator/stereo/triangle_remeshing.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// The projections and centres of the views, for the remeshing's edge test.
struct ViewGeometry {
  Eigen::Matrix<double, 3, 4> projection;
  Eigen::Vector3d centre;
  int width = 0, height = 0;
};

// Length in pixels of the edge a-b in the view that faces its mean normal best among those
// that see its midpoint in their image; 0 when none does.
double EdgePixels(const std::vector<ViewGeometry>& views, const Eigen::Vector3d& a,
                  const Eigen::Vector3d& b, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d middle = 0.5 * (a + b);
  double best_cos = -std::numeric_limits<double>::infinity(), pixels = 0;
  for (const ViewGeometry& view : views) {
    const double facing = normal.dot((view.centre - middle).normalized());
    if (facing <= best_cos) continue;
    const Eigen::Vector3d pa = view.projection * a.homogeneous();
    const Eigen::Vector3d pb = view.projection * b.homogeneous();
    const Eigen::Vector3d pm = view.projection * middle.homogeneous();
    if (pa.z() <= 0 || pb.z() <= 0 || pm.z() <= 0) continue;
    const Eigen::Vector2d m = pm.head<2>() / pm.z();
    if (m.x() < 0 || m.y() < 0 || m.x() > view.width - 1 || m.y() > view.height - 1) continue;
    best_cos = facing;
    pixels = (pa.head<2>() / pa.z() - pb.head<2>() / pb.z()).norm();
  }
  return pixels;
}

// Splits the edges longer than max_edge_px in their best view; anchors follow (a new vertex's
// anchor is the middle of its edge's). Returns the edges split.
size_t Remesh(const std::vector<ViewGeometry>& views, const SurfaceRefinementOptions& options,
              TriangleMesh* mesh, std::vector<Eigen::Vector3f>* anchors) {
  const std::vector<Eigen::Vector3d> normals = VertexNormals(*mesh);
  const EdgeSplitTest too_long = [&](int32_t a, int32_t b) {
    const auto ia = static_cast<size_t>(a), ib = static_cast<size_t>(b);
    return EdgePixels(views, mesh->vertices[ia].cast<double>(), mesh->vertices[ib].cast<double>(),
                      (normals[ia] + normals[ib]).normalized()) > options.max_edge_px;
  };
  SubdivisionStats split;
  std::vector<std::array<int32_t, 2>> parents;
  if (!SubdivideLongEdges(mesh, too_long, options.max_triangles, &split, &parents)) return 0;
  for (const auto& [a, b] : parents)
    anchors->push_back(0.5f *
                       ((*anchors)[static_cast<size_t>(a)] + (*anchors)[static_cast<size_t>(b)]));
  return split.edges_split + split.closure;
}

// Moves vertex i by offsets[i] (clamped to +-max_step) along its normal, into its box.
void MoveAlongNormals(const std::vector<Eigen::Vector3d>& normals,
                      const std::vector<double>& offsets, double max_step,
                      const std::vector<Eigen::Vector3f>& lo,
                      const std::vector<Eigen::Vector3f>& hi, TriangleMesh* mesh) {
  for (size_t i = 0; i < mesh->vertices.size(); ++i) {
    const double offset = std::clamp(offsets[i], -max_step, max_step);
    mesh->vertices[i] = (mesh->vertices[i].cast<double>() + offset * normals[i])
                            .cast<float>()
                            .cwiseMax(lo[i])
                            .cwiseMin(hi[i]);
  }
}

}  // namespace

bool SurfaceRefinementOptions::IsValid(std::string* reason) const {
  const auto fail = [&](const char* why) {
    if (reason) *reason = why;
    return false;
  };
  if (iterations < 0) return fail("iterations must not be negative");
  if (!(search_footprints > 0 && search_step_footprints > 0))
    return fail("the texture search range and step must be positive");
  if (!(texture_rate > 0 && texture_rate <= 1)) return fail("texture_rate must be in (0, 1]");
  if (!(max_step_footprints > 0 && max_shift_footprints > 0))
    return fail("the largest step and shift must be positive");
  if (!(max_edge_px >= 0)) return fail("max_edge_px must not be negative");
  if (smoothing_pairs < 0 || curvature_rounds < 0 || restore_rounds < 0)
    return fail("smoothing pairs, curvature and restore rounds must not be negative");
  std::string patch_reason;
  if (!patch.IsValid(&patch_reason)) {
    if (reason) *reason = "patch: " + patch_reason;
    return false;
  }
  if (!(silhouettes.rim_cos >= 0 && silhouettes.rim_cos < 1 && silhouettes.rim_distance_px >= 0))
    return fail("the rim test needs rim_cos in [0, 1) and rim_distance_px >= 0");
  std::string reach_reason;
  if (!reach.IsValid(&reach_reason)) {
    if (reason) *reason = reach_reason;
    return false;
  }
  return true;
}

TriangleMesh RefineSurface(const TriangleMesh& surface, const std::vector<StereoView>& views,
                           const PatchScorer& scorer, double footprint,
                           const SurfaceRefinementOptions& options, SurfaceRefinementStats* stats,
                           Progress* progress) {
  SILNET_CHECK(footprint > 0);
  std::string why;
  SILNET_CHECK_MSG(options.IsValid(&why), why);
  const auto start = std::chrono::steady_clock::now();
  SurfaceRefinementStats local;
  SurfaceRefinementStats& s = stats ? *stats : local;
  s = SurfaceRefinementStats{};
  s.vertices_in = surface.vertices.size();
  s.triangles_in = surface.triangles.size();
  TriangleMesh mesh = surface;
  std::vector<Eigen::Vector3f> anchors = mesh.vertices;
  std::vector<cv::Mat> covered;
  if (options.restore_rounds > 0 && options.iterations > 0)
    covered = CoveredInnerPixels(surface, views);

  std::vector<ViewGeometry> geometry;
  for (const StereoView& view : views)
    geometry.push_back({view.camera.ProjectionMatrix(), view.camera.Center(), view.camera.width,
                        view.camera.height});
  const SilhouetteForce silhouette(views, options.silhouettes);
  TextureForceOptions texture;
  texture.range = options.search_footprints * footprint;
  texture.step = options.search_step_footprints * footprint;
  texture.patch_step = footprint;
  texture.min_score = options.min_score;
  const double max_step = options.max_step_footprints * footprint;
  const auto max_shift = static_cast<float>(options.max_shift_footprints * footprint);

  // Each vertex's box: +-max_shift around its anchor.
  const auto boxes = [&](std::vector<Eigen::Vector3f>* lo, std::vector<Eigen::Vector3f>* hi) {
    lo->resize(anchors.size());
    hi->resize(anchors.size());
    for (size_t i = 0; i < anchors.size(); ++i) {
      (*lo)[i] = anchors[i].array() - max_shift;
      (*hi)[i] = anchors[i].array() + max_shift;
    }
  };
  std::vector<Eigen::Vector3f> lo, hi;
  if (progress) progress->Restart("refinement", static_cast<size_t>(options.iterations));
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    if (progress && progress->cancelled()) {
      s.cancelled = true;
      break;
    }
    if (options.max_edge_px > 0) s.split_edges += Remesh(geometry, options, &mesh, &anchors);
    const std::vector<Eigen::Vector3d> normals = VertexNormals(mesh);
    const VertexNeighbours neighbours = FindVertexNeighbours(mesh);
    // Two iterations search the whole range, the rest its middle half: by then the surface
    // is within a footprint of where the patches want it.
    texture.range = (iteration < 2 ? 1.0 : 0.5) * options.search_footprints * footprint;
    const std::vector<NormalOffset> rims = silhouette.AtVertices(mesh, normals, options.threads);
    std::vector<uint8_t> on_rim(rims.size());
    for (size_t i = 0; i < rims.size(); ++i)
      on_rim[i] = rims[i].weight > 0 ? 1 : 0;
    const std::vector<NormalOffset> textured = TextureForces(
        mesh, normals, VertexCurvatures(mesh, neighbours, normals, options.curvature_rounds),
        scorer, texture, options.threads, on_rim);
    // The silhouettes where they pull, else the texture's part.
    std::vector<double> offsets(mesh.vertices.size(), 0.0);
    s.textured = s.rims = 0;
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      if (rims[i].weight > 0) {
        offsets[i] = rims[i].offset;
        ++s.rims;
      } else if (textured[i].weight > 0) {
        offsets[i] = options.texture_rate * textured[i].offset;
        ++s.textured;
      }
    }
    boxes(&lo, &hi);
    MoveAlongNormals(normals, offsets, max_step, lo, hi, &mesh);
    TaubinSmooth(&mesh, neighbours, options.smoothing_pairs, options.smoothing_lambda,
                 options.smoothing_mu, lo, hi);
    if (progress) progress->Advance();
  }
  if (!covered.empty() && !s.cancelled) {
    const CoverageRestoreStats restore =
        RestoreCoverage(views, covered, anchors, options.restore_rounds, &mesh);
    s.restored = restore.restored;
    s.still_uncovered = restore.still_uncovered;
  }
  if (!s.cancelled && options.iterations > 0 && options.reach.rounds > 0) {
    PixelReachOptions reach = options.reach;
    reach.threads = options.threads;
    s.reach = ReachMissedPixels(views, footprint, reach, &mesh);
  }
  s.vertices = mesh.vertices.size();
  s.triangles = mesh.triangles.size();
  double shift = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    shift += (mesh.vertices[i] - anchors[i]).norm();
  s.mean_shift = mesh.vertices.empty() ? 0 : shift / static_cast<double>(mesh.vertices.size());
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

}  // namespace silnet::aggregator
