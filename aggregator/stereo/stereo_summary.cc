// stereo.yaml: what the stereo job did, for tools and tests (the layout WriteStereoSummary in
// stereo_job.h writes).

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <opencv2/core/persistence.hpp>

#include "aggregator/stereo/stereo_job.h"
#include "aggregator/stereo/stereo_truth.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

int AsInt(size_t value) {
  return static_cast<int>(std::min<size_t>(value, static_cast<size_t>(INT32_MAX)));
}

void WriteEvaluation(cv::FileStorage& fs, const ModelEvaluation& e) {
  fs << "{"
     << "accuracy_mm" << e.accuracy_m * 1e3 << "accuracy_footprints" << e.accuracy_footprints
     << "mean_distance_mm" << e.mean_distance_m * 1e3 << "model_samples" << AsInt(e.model_samples)
     << "completeness"
     << "[";
  for (const Completeness& c : e.completeness) {
    fs << "{"
       << "within_footprints" << c.distance_footprints << "within_mm" << c.distance_m * 1e3
       << "fraction" << c.fraction << "}";
  }
  fs << "]";
  if (!e.regions.empty()) {
    fs << "regions"
       << "{";
    for (const RegionEvaluation& r : e.regions) {
      fs << r.name << "{"
         << "truth_points" << AsInt(r.truth_points) << "accuracy_mm" << r.accuracy_m * 1e3
         << "accuracy_footprints" << r.accuracy_footprints << "completeness"
         << "[";
      for (const Completeness& c : r.completeness)
        fs << "{"
           << "within_footprints" << c.distance_footprints << "fraction" << c.fraction << "}";
      fs << "]"
         << "}";
    }
    fs << "}";
  }
  fs << "}";
}

void WriteMesh(cv::FileStorage& fs, const std::string& name, const StereoMeshSummary& m) {
  fs << name << "{"
     << "file" << m.file << "vertices" << AsInt(m.vertices) << "faces" << AsInt(m.triangles)
     << "closed_manifold" << static_cast<int>(m.closed_manifold) << "pieces" << AsInt(m.pieces)
     << "main_genus" << static_cast<int>(m.main_genus) << "volume_m3" << m.volume_m3;
  if (!m.views.empty()) {
    fs << "missed_inner_pixels" << AsInt(m.MissedInner()) << "missed_uncoverable_pixels"
       << AsInt(m.MissedUncoverable()) << "covered_outer_pixels" << AsInt(m.CoveredOuter())
       << "covered_outer_traded_pixels" << AsInt(m.CoveredOuterTraded());
  }
  if (m.evaluation) {
    fs << "evaluation";
    WriteEvaluation(fs, *m.evaluation);
  }
  fs << "}";
}

// The adaptive stereo's figures.
void WriteAdaptive(cv::FileStorage& fs, const AdaptiveStereoStats& a) {
  fs << "adaptive"
     << "{"
     << "cells" << AsInt(a.cells) << "links" << AsInt(a.links) << "faces_scored"
     << AsInt(a.faces_scored) << "quasi_dense_points" << AsInt(a.quasi_dense_points)
     << "finest_spacing_mm" << a.finest_spacing * 1e3 << "cells_outside_hull"
     << AsInt(a.labels.outside_hull) << "cells_interior" << AsInt(a.labels.interior)
     << "cells_forced" << AsInt(a.forced) << "cells_forced_outside" << AsInt(a.forced_out)
     << "cells_added_for_manifold" << AsInt(a.repaired) << "ballooning_factor"
     << a.ballooning_factor << "missed_inner_share_per_raise"
     << "[";
  for (double share : a.missed_share)
    fs << share;
  fs << "]"
     << "missed_inner_per_round"
     << "[";
  for (size_t m : a.missed)
    fs << AsInt(m);
  fs << "]"
     << "covered_outer_per_round"
     << "[";
  for (size_t c : a.covered)
    fs << AsInt(c);
  fs << "]"
     << "levels"
     << "[";
  for (const AdaptiveLevelStats& l : a.levels) {
    fs << "{"
       << "level" << l.level << "spacing_mm" << l.spacing * 1e3 << "cells" << AsInt(l.cells)
       << "faces_sampled" << AsInt(l.faces_sampled) << "samples_scored" << AsInt(l.samples_scored)
       << "active_cells" << AsInt(l.active_cells) << "refined_cells" << AsInt(l.refined_cells)
       << "seconds" << l.seconds << "seconds_sampling" << l.seconds_sampling << "}";
  }
  fs << "]"
     << "seconds"
     << "{"
     << "mesh" << a.seconds_mesh << "labels" << a.seconds_labels << "cut" << a.seconds_cut
     << "max_flow" << a.seconds_max_flow << "silhouettes" << a.seconds_silhouettes << "surface"
     << a.seconds_surface << "}"
     << "}";
}

// The local refinement's settings and figures.
void WriteRefinement(cv::FileStorage& fs, const SurfaceRefinementOptions& o,
                     const SurfaceRefinementStats& r) {
  fs << "refinement"
     << "{"
     << "iterations" << o.iterations << "search_footprints" << o.search_footprints << "min_score"
     << o.min_score << "max_edge_px" << o.max_edge_px << "vertices_in" << AsInt(r.vertices_in)
     << "vertices" << AsInt(r.vertices) << "edges_split" << AsInt(r.split_edges)
     << "textured_vertices" << AsInt(r.textured) << "rim_vertices" << AsInt(r.rims)
     << "mean_shift_mm" << r.mean_shift * 1e3 << "vertices_restored" << AsInt(r.restored)
     << "pixels_still_uncovered" << AsInt(r.still_uncovered) << "reach"
     << "{"
     << "rounds" << AsInt(r.reach.rounds) << "missed_inner_before" << AsInt(r.reach.missed_before)
     << "coverable_before" << AsInt(r.reach.coverable_before) << "vertices_moved"
     << AsInt(r.reach.moved) << "moves_undone" << AsInt(r.reach.undone) << "missed_inner_after"
     << AsInt(r.reach.missed_after) << "seconds" << r.reach.seconds << "}"
     << "seconds" << r.seconds << "}";
}

}  // namespace

void WriteStereoSummary(const StereoJobConfig& config, const StereoJobResult& result) {
  const std::filesystem::path path = config.output / "stereo.yaml";
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw InputError(fmt::format("cannot write {}", path.string()));
  fs << "format_version" << 1;
  fs << "input" << config.input.string() << "calibration" << config.calibration.string() << "still"
     << config.still;
  fs << "success" << static_cast<int>(result.success);
  if (!result.success) fs << "reason" << result.reason;
  if (config.method == StereoMethod::kAdaptive) {
    fs << "method"
       << "adaptive tetrahedral graph cut (thesis 7.3-7.4.2)";
  } else {
    const bool exact = config.constraints == SilhouetteConstraints::kExact;
    fs << "method"
       << (exact ? std::string("volumetric graph cut with exact silhouette constraints, "
                               "Formulation I (thesis 6.4-6.6)")
                 : fmt::format("volumetric graph cut (thesis 5.4.1){}",
                               config.graph_cut.silhouette_rounds > 0
                                   ? fmt::format(", up to {} silhouette steps (7.4.2)",
                                                 config.graph_cut.silhouette_rounds)
                                   : ""));
  }
  if (config.method == StereoMethod::kAdaptive) {
    const AdaptiveTetMeshOptions& mesh = config.adaptive.mesh;
    const TetGraphCutOptions& cut = config.adaptive.cut;
    fs << "settings"
       << "{"
       << "base_cells_footprints" << mesh.base_spacing_footprints << "finest_cells_footprints"
       << mesh.finest_spacing_footprints << "sample_spacing_footprints"
       << mesh.sample_spacing_footprints << "min_score" << mesh.min_score << "lambda" << cut.lambda
       << "ballooning" << cut.ballooning << "threads" << config.threads << "}";
  } else {
    const PhotoConsistencyOptions& photo = config.photo_consistency;
    const VolumetricGraphCutOptions& cut = config.graph_cut;
    fs << "settings"
       << "{"
       << "neighbours" << photo.neighbours.count << "window" << photo.matching.window << "min_ncc"
       << photo.matching.min_ncc << "pixel_step" << photo.pixel_step << "cell_size_footprints"
       << photo.cell_size_footprints << "lambda" << cut.lambda << "ballooning" << cut.ballooning
       << "inner_offset_fraction" << cut.inner_offset_fraction << "threads" << config.threads
       << "}";
  }
  fs << "views" << AsInt(result.views) << "warnings"
     << "[";
  for (const std::string& warning : result.warnings)
    fs << warning;
  fs << "]";
  fs << "footprint_mm" << result.footprint * 1e3;
  fs << "lattice"
     << "{"
     << "dims"
     << "[" << result.lattice_dims[0] << result.lattice_dims[1] << result.lattice_dims[2] << "]"
     << "cell_size_mm" << result.cell_size * 1e3 << "votes_in_hull"
     << AsInt(result.photo_consistency.votes_in_hull) << "matches"
     << AsInt(result.photo_consistency.matches) << "}";
  const VolumetricGraphCutStats& g = result.graph_cut;
  fs << "graph"
     << "{"
     << "hull_cells" << AsInt(g.hull_cells) << "pocket_cells" << AsInt(g.pocket_cells) << "nodes"
     << AsInt(g.nodes) << "n_links" << AsInt(g.n_links) << "t_link_faces" << AsInt(g.t_link_faces)
     << "interior_cells" << AsInt(g.interior_cells) << "silhouette_rounds" << g.silhouette_rounds
     << "forced_cells" << AsInt(g.forced_cells) << "joined_pixels" << AsInt(g.joined_pixels)
     << "graph_bytes" << static_cast<double>(g.graph_bytes) << "lattice_bytes"
     << static_cast<double>(g.lattice_bytes) << "cut_cost" << g.cut_cost << "}";
  if (result.exact_constraints) {
    const ExactConstraintStats& e = *result.exact_constraints;
    fs << "exact_constraints"
       << "{"
       << "segments" << AsInt(e.colouring.segments) << "false_segments"
       << AsInt(e.colouring.false_segments) << "strip_repairs"
       << AsInt(e.colouring.connecting_curves) << "unconnected_repairs"
       << AsInt(e.colouring.unconnected) << "green_vertices" << AsInt(e.colouring.green_vertices)
       << "hidden_rim_labels" << AsInt(e.colouring.hidden_rim) << "surface_layer_cells"
       << AsInt(e.layer_cells) << "red_cells" << AsInt(e.red_cells) << "blue_cells"
       << AsInt(e.blue_cells) << "clashes" << AsInt(e.clashes) << "twisted_cells"
       << AsInt(e.twisted_cells) << "seconds_colouring" << e.seconds_colouring << "}";
  }
  if (result.adaptive) WriteAdaptive(fs, *result.adaptive);
  const StereoStageTimes& s = result.seconds;
  fs << "seconds"
     << "{"
     << "load" << s.load << "hull" << s.hull << "photo_consistency" << s.photo_consistency
     << "graph_cut" << s.graph_cut << "refinement" << s.refinement << "evaluation" << s.evaluation
     << "pictures" << s.pictures << "total" << s.total << "}";
  WriteMesh(fs, "hull", result.hull);
  WriteMesh(fs, "model", result.model);
  if (result.cut.triangles > 0) WriteMesh(fs, "cut", result.cut);
  if (result.refinement) WriteRefinement(fs, config.refinement, *result.refinement);
  if (result.redundant_pieces) {
    const RedundantPieceStats& pieces = *result.redundant_pieces;
    fs << "redundant_pieces"
       << "{"
       << "pieces_before" << AsInt(pieces.pieces_before) << "removed" << AsInt(pieces.removed)
       << "triangles_removed" << AsInt(pieces.triangles_removed) << "seconds" << pieces.seconds
       << "}";
  }
  fs << "silhouettes"
     << "[";
  for (size_t v = 0; v < result.model.views.size(); ++v) {
    const SilhouetteConsistency& m = result.model.views[v];
    fs << "{"
       << "camera" << m.camera_id << "silhouette_pixels" << AsInt(m.silhouette_pixels)
       << "inner_pixels" << AsInt(m.inner_pixels) << "missed_inner" << AsInt(m.missed_inner)
       << "missed_uncoverable" << AsInt(m.missed_uncoverable) << "outer_pixels"
       << AsInt(m.outer_pixels) << "covered_outer" << AsInt(m.covered_outer)
       << "covered_outer_traded" << AsInt(m.covered_outer_traded);
    if (v < result.hull.views.size()) {
      fs << "hull_missed_inner" << AsInt(result.hull.views[v].missed_inner)
         << "hull_missed_uncoverable" << AsInt(result.hull.views[v].missed_uncoverable)
         << "hull_covered_outer" << AsInt(result.hull.views[v].covered_outer)
         << "hull_covered_outer_traded" << AsInt(result.hull.views[v].covered_outer_traded);
    }
    fs << "}";
  }
  fs << "]";
}

}  // namespace silnet::aggregator
