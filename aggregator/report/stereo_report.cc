#include "aggregator/report/stereo_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <exception>
#include <string>
#include <utility>
#include <vector>

#include "aggregator/hulls/ply_io.h"
#include "aggregator/report/display_mesh.h"
#include "aggregator/report/html_table.h"
#include "aggregator/report/mesh_viewer.h"

namespace silnet::aggregator {
namespace {

const char* const kNone = "\u2014";  // em dash for "no value"

std::string Paragraph(const std::string& text, const char* css_class = nullptr) {
  return css_class ? fmt::format("<p class=\"{}\">{}</p>\n", css_class, EscapeHtml(text))
                   : fmt::format("<p>{}</p>\n", EscapeHtml(text));
}

std::string JobSummary(const StereoJobConfig& config, const StereoJobResult& result) {
  std::string html;
  if (result.success) {
    html += Paragraph(fmt::format(
        "Model: {} triangles, {} vertices, closed and manifold, from {} views of {} (still {}).",
        result.model.triangles, result.model.vertices, result.views, config.input.string(),
        config.still));
  } else {
    html += Paragraph(fmt::format("No model: {}", result.reason), "bad");
  }
  HtmlTable table(std::vector<std::string>{});
  table.AddRow({"pixel footprint at the object",
                result.footprint > 0 ? fmt::format("{:.3f} mm", result.footprint * 1e3) : kNone});
  table.AddRow(
      {"method", config.method == StereoMethod::kAdaptive
                     ? "adaptive tetrahedral graph cut (thesis ch. 7)"
                     : "votes on a uniform lattice, volumetric graph cut (thesis ch. 5-6)"});
  if (result.adaptive) {
    table.AddRow(
        {"adaptive mesh",
         fmt::format("{} tetrahedra, finest cubes of {:.3f} mm, {} levels", result.adaptive->cells,
                     result.adaptive->finest_spacing * 1e3, result.adaptive->levels.size())});
  } else {
    table.AddRow({"vote lattice",
                  result.cell_size > 0
                      ? fmt::format("{} cells of {:.3f} mm", fmt::join(result.lattice_dims, " x "),
                                    result.cell_size * 1e3)
                      : kNone});
  }
  if (result.refinement) {
    const SurfaceRefinementStats& r = *result.refinement;
    table.AddRow({"local refinement (thesis 7.4.3)",
                  fmt::format("{} iterations, {} vertices to {}, mean move {:.2f} mm, {:.1f} s",
                              config.refinement.iterations, r.vertices_in, r.vertices,
                              r.mean_shift * 1e3, r.seconds)});
    if (r.reach.coverable_before > 0) {
      table.AddRow(
          {"missed silhouette pixels reached",
           fmt::format("{} of {} that a consistent model covers, {} vertices moved ({} "
                       "moves undone), {:.1f} s",
                       r.reach.missed_before - r.reach.missed_after, r.reach.coverable_before,
                       r.reach.moved, r.reach.undone, r.reach.seconds)});
    }
  }
  if (result.redundant_pieces && result.redundant_pieces->removed > 0) {
    const RedundantPieceStats& pieces = *result.redundant_pieces;
    table.AddRow({"floating pieces removed",
                  fmt::format("{} of {} ({} triangles): the rest covers every silhouette pixel "
                              "they cover, {:.1f} s",
                              pieces.removed, pieces.pieces_before, pieces.triangles_removed,
                              pieces.seconds)});
  }
  table.AddRow({"total time", fmt::format("{:.1f} s", result.seconds.total)});
  html += table.ToHtml();
  if (!result.warnings.empty()) {
    html += "<ul class=\"bad\">\n";
    for (const std::string& warning : result.warnings)
      html += fmt::format("<li>{}</li>\n", EscapeHtml(warning));
    html += "</ul>\n";
  }
  return html;
}

// "count" alone, or "count (part label)" when part of it is of that kind.
std::string WithShare(size_t count, size_t part, const char* label) {
  return part == 0 ? std::to_string(count) : fmt::format("{} ({} {})", count, part, label);
}

// "6.20 mm (1.06 fp)" and "61.0 % within 1 fp, 73.9 % within 2 fp".
std::string AccuracyText(double metres, double footprints) {
  return fmt::format("{:.2f} mm ({:.2f} fp)", metres * 1e3, footprints);
}
std::string CompletenessText(const std::vector<Completeness>& completeness) {
  std::vector<std::string> within;
  for (const Completeness& c : completeness)
    within.push_back(
        fmt::format("{:.1f} % within {:g} fp", 100 * c.fraction, c.distance_footprints));
  return fmt::format("{}", fmt::join(within, ", "));
}

// What each region of the truth is, for the report.
std::string RegionDescription(const RegionEvaluation& region) {
  if (region.name == kConcaveRegion) {
    return fmt::format(
        "Concave region: the {} true points the visual hull misses by more than "
        "{:g} footprints.",
        region.truth_points, kConcaveRegionFootprints);
  }
  if (region.name == kTJunctionRegion) {
    return fmt::format(
        "T-junctions: the {} true points near a view's rim that project within "
        "3 px of an inward corner of its silhouette (where one part's outline "
        "ends against another's).",
        region.truth_points);
  }
  return fmt::format("{}: {} true points.", region.name, region.truth_points);
}

// Model and hull over each region of the truth, when the truth gave them.
std::string RegionTables(const StereoJobResult& result) {
  if (!result.model.evaluation || !result.hull.evaluation) return {};
  std::string html;
  for (const RegionEvaluation& model : result.model.evaluation->regions) {
    const RegionEvaluation* hull = result.hull.evaluation->Region(model.name);
    HtmlTable table({"mesh", "accuracy (90 %)", "completeness"});
    table.AddRow({"model", AccuracyText(model.accuracy_m, model.accuracy_footprints),
                  CompletenessText(model.completeness)});
    if (result.cut.evaluation) {
      if (const RegionEvaluation* cut = result.cut.evaluation->Region(model.name)) {
        table.AddRow({"graph-cut surface", AccuracyText(cut->accuracy_m, cut->accuracy_footprints),
                      CompletenessText(cut->completeness)});
      }
    }
    if (hull != nullptr) {
      table.AddRow({"visual hull", AccuracyText(hull->accuracy_m, hull->accuracy_footprints),
                    CompletenessText(hull->completeness)});
    }
    html += Paragraph(RegionDescription(model)) + table.ToHtml();
  }
  return html;
}

std::string MeshTable(const StereoJobResult& result) {
  HtmlTable table({"mesh", "triangles", "closed manifold", "parts", "genus of the largest",
                   "volume (cm\u00b3)", "inner silhouette px missed", "outer px covered",
                   "accuracy (90 %)", "completeness"});
  const auto add = [&table](const std::string& name, const StereoMeshSummary& m) {
    if (m.triangles == 0) return;
    std::string accuracy = kNone, completeness = kNone;
    if (m.evaluation) {
      accuracy = AccuracyText(m.evaluation->accuracy_m, m.evaluation->accuracy_footprints);
      completeness = CompletenessText(m.evaluation->completeness);
    }
    table.AddRow(
        {name, std::to_string(m.triangles), m.closed_manifold ? "yes" : "no",
         std::to_string(m.pieces), std::to_string(m.main_genus),
         fmt::format("{:.1f}", m.volume_m3 * 1e6),
         m.views.empty() ? kNone : WithShare(m.MissedInner(), m.MissedUncoverable(), "uncoverable"),
         m.views.empty() ? kNone : WithShare(m.CoveredOuter(), m.CoveredOuterTraded(), "traded"),
         accuracy, completeness},
        m.closed_manifold ? "" : "bad");
  };
  add("model", result.model);
  add("graph-cut surface (before refinement)", result.cut);
  add("visual hull", result.hull);
  return table.ToHtml("no mesh") + RegionTables(result) +
         Paragraph(
             "Silhouette pixels count when their centre lies at least 1 px inside the "
             "outline (missed) or outside it (covered); an exactly silhouette-consistent "
             "model has 0 and 0. Uncoverable: missed pixels whose viewing ray meets no point "
             "less than 1 px outside every other view's silhouette, where the cameras and "
             "silhouettes disagree; no consistent model covers them. Traded: covered pixels "
             "where the model's surface covers another view's uncoverable pixel, the price "
             "of covering it. Accuracy and "
             "completeness are measured against the simulation's true surface "
             "(gt_surface.ply) when the stills have one; fp = pixel footprints at the object.",
             "muted");
}

std::string StageTable(const StereoJobResult& result) {
  const StereoStageTimes& s = result.seconds;
  HtmlTable table({"stage", "seconds"});
  const std::vector<std::pair<const char*, double>> stages = {
      {"load", s.load},
      {"visual hull", s.hull},
      {"photo-consistency", s.photo_consistency},
      {"graph cut", s.graph_cut},
      {"refinement", s.refinement},
      {"evaluation", s.evaluation},
      {"pictures", s.pictures},
      {"total", s.total}};
  for (const auto& [name, seconds] : stages)
    table.AddRow({name, fmt::format("{:.2f}", seconds)});
  return table.ToHtml();
}

std::string GraphTable(const StereoJobResult& result) {
  const VolumetricGraphCutStats& g = result.graph_cut;
  HtmlTable table(std::vector<std::string>{});
  table.AddRow({"hull cells", fmt::format("{} ({} inner pockets)", g.hull_cells, g.pocket_cells)});
  table.AddRow({"graph", fmt::format("{} nodes, {} n-links, {:.1f} MB", g.nodes, g.n_links,
                                     static_cast<double>(g.graph_bytes) / 1e6)});
  table.AddRow({"silhouette steps",
                g.missed_pixels_per_round.empty()
                    ? std::string("none")
                    : fmt::format("{} re-solves, {} cells forced ({} pixels' cells joined to the "
                                  "model); inner pixels missed per round: {}",
                                  g.silhouette_rounds, g.forced_cells, g.joined_pixels,
                                  fmt::join(g.missed_pixels_per_round, ", "))});
  table.AddRow({"interior cells", std::to_string(g.interior_cells)});
  return table.ToHtml();
}

std::string ViewTable(const StereoJobResult& result) {
  HtmlTable table({"camera", "silhouette px", "inner px", "missed by model", "missed by hull",
                   "outer px covered by model", "by hull"});
  for (size_t v = 0; v < result.model.views.size(); ++v) {
    const SilhouetteConsistency& m = result.model.views[v];
    const bool hull = v < result.hull.views.size();
    table.AddRow({m.camera_id, std::to_string(m.silhouette_pixels), std::to_string(m.inner_pixels),
                  WithShare(m.missed_inner, m.missed_uncoverable, "uncoverable"),
                  hull ? WithShare(result.hull.views[v].missed_inner,
                                   result.hull.views[v].missed_uncoverable, "uncoverable")
                       : kNone,
                  WithShare(m.covered_outer, m.covered_outer_traded, "traded"),
                  hull ? WithShare(result.hull.views[v].covered_outer,
                                   result.hull.views[v].covered_outer_traded, "traded")
                       : kNone},
                 m.missed_inner > 0 || m.covered_outer > 0 ? "warn" : "");
  }
  std::string html = table.ToHtml("no view was measured");
  if (result.view_pictures.empty()) return html;
  html += Paragraph(
      "Each view: the photograph, the model shaded from that camera, and the model's coverage "
      "against the silhouette (white covered, red silhouette missed, blue covered outside it).",
      "muted");
  for (const std::string& picture : result.view_pictures) {
    html += fmt::format(
        "<figure><img src=\"{0}\" alt=\"{0}\" loading=\"lazy\"><figcaption>{0}"
        "</figcaption></figure>\n",
        EscapeHtml(picture));
  }
  return html;
}

// The model and the hull to turn in 3D (the job wrote both as PLY), or why they cannot be.
std::string ThreeDView(const StereoJobConfig& config, const StereoJobResult& result) {
  const std::string missing = InstallMeshViewer(config.output);
  if (!missing.empty()) return Paragraph("No 3D view: " + missing, "bad");
  try {
    const std::pair<const char*, const std::string*> meshes[] = {{"model", &result.model.file},
                                                                 {"hull", &result.hull.file}};
    for (const auto& [name, file] : meshes) {
      WriteViewerMesh(config.output, name,
                      MakeDisplayMesh(ReadPlyMesh((config.output / *file).string())));
    }
  } catch (const std::exception& error) {
    return Paragraph(fmt::format("No 3D view: {}", error.what()), "bad");
  }
  ViewerLayer model{"model", "stereo model"};
  ViewerLayer hull{"hull", "visual hull (wireframe)", 0x6fa8dc, true, false};
  // Seen at first as the first photograph sees it (image rows run down).
  std::optional<ViewerStart> start;
  if (!result.cameras.empty()) {
    const CameraModel& camera = result.cameras.front();
    start = ViewerStart{camera.Center(), -(camera.R.transpose() * Eigen::Vector3d::UnitY())};
  }
  return Paragraph(
             "The model (and, ticked, the visual hull it was cut from), reduced for the browser "
             "to at most 150 000 triangles; model.ply has them all.") +
         MeshViewerHtml("stereo-view", {model, hull}, start);
}

}  // namespace

void WriteStereoReport(const StereoJobConfig& config, const StereoJobResult& result) {
  std::string html = Section("Summary", JobSummary(config, result));
  if (result.success) html += Section("3D view", ThreeDView(config, result));
  html += Section("Model and visual hull", MeshTable(result));
  html += Section("Stages", StageTable(result));
  if (result.graph_cut.nodes > 0) html += Section("Graph cut", GraphTable(result));
  html += Section("Views", ViewTable(result));
  WriteHtmlPage(config.output / "report.html", "silnet stereo report", html);
}

}  // namespace silnet::aggregator
