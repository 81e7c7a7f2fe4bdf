#include "aggregator/live/live_report.h"

#include <fmt/format.h>

#include <exception>
#include <opencv2/core/persistence.hpp>
#include <optional>
#include <vector>

#include "aggregator/hulls/ply_io.h"
#include "aggregator/report/display_mesh.h"
#include "aggregator/report/html_table.h"
#include "aggregator/report/mesh_viewer.h"
#include "aggregator/report/report_sections.h"
#include "shared/io/replace_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

std::string Percent(double fraction) {
  return fmt::format("{:.2f} %", 100 * fraction);
}

std::string IngestSection(const LiveJobResult& r) {
  HtmlTable table({"camera", "session", "frames held", "missing", "received", "contours",
                   "duplicates", "out of order", "malformed", "re-send requests", "stalls",
                   "store failures", "node dropped", "node flagged", "node"});
  for (const CameraIngestStatus& c : r.cameras) {
    table.AddRow({c.camera_id, std::to_string(c.session), std::to_string(c.frames_held),
                  std::to_string(c.missing), std::to_string(c.received), std::to_string(c.contours),
                  std::to_string(c.duplicates), std::to_string(c.out_of_order),
                  std::to_string(c.malformed), std::to_string(c.resend_requests),
                  std::to_string(c.stalls), std::to_string(c.store_failures),
                  std::to_string(c.node_dropped), std::to_string(c.node_flagged), c.node_state},
                 c.missing > 0 || c.malformed > 0 || c.node_dropped > 0 ? "warn" : "");
  }
  return fmt::format(
             "<p>{} samples received, {} frames held, {} missing; DDS lost {} and "
             "rejected {} samples; the nodes dropped {} frames (never captured or not "
             "processed, e.g. while overloaded) and flagged {} (published as empty, saturated, "
             "unusable, dropped or still warming up).</p>\n",
             r.ingest.received, r.ingest.stored, r.ingest.missing, r.ingest.dds_samples_lost,
             r.ingest.dds_samples_rejected, r.ingest.node_dropped, r.ingest.node_flagged) +
         table.ToHtml();
}

std::string CalibrationSection(const LiveJobResult& r) {
  if (!r.calibration) return "<p class=\"muted\">no calibration</p>\n";
  const NetworkCalibration& c = r.calibration->calibration;
  std::string html = fmt::format(
      "<p>From the first {} frames of every camera (attempt {}); {} in {:.1f} s. Full report: "
      "<a href=\"calibration/report/report.html\">calibration/report/report.html</a>.</p>\n",
      r.calibration_frames, r.calibration_attempts,
      r.published ? "published on DDS" : "not published", r.calibration->seconds);
  html += SummarySection(c);
  html +=
      "<figure><img src=\"calibration/report/plots/camera_network.png\" alt=\"camera "
      "network\"><figcaption>The calibrated cameras and frontier points.</figcaption>"
      "</figure>\n";
  html +=
      "<figure><img src=\"calibration/report/plots/offsets_graph.png\" alt=\"offsets\">"
      "<figcaption>Time offsets (frames) and the pairwise measurements.</figcaption>"
      "</figure>\n";
  if (r.calibration->errors)
    html += Section("Against ground truth", GroundTruthSection(*r.calibration->errors));
  return html;
}

std::string TruthCell(double value, const char* format) {
  return value < 0.0 ? "-" : fmt::format(fmt::runtime(format), value);
}

std::string MovedCamerasSection(const LiveJobResult& r) {
  if (r.camera_moves.empty()) {
    return fmt::format(
        "<p>{} checks of every camera pair's epipolar residuals against the calibration in use; "
        "no camera moved (status in <a href=\"camera_motion.yaml\">camera_motion.yaml</a>).</p>\n",
        r.motion_checks);
  }
  HtmlTable table({"camera", "detected at frame", "residual px (before)", "pairs jumped",
                   "re-estimated", "from frame", "rms px", "rotation vs truth", "note"});
  for (const CameraMoveEvent& e : r.camera_moves) {
    table.AddRow(
        {e.camera_id, std::to_string(e.detected_frame),
         fmt::format("{:.2f} ({:.2f})", e.residual_px, e.baseline_px),
         fmt::format("{} of {}", e.pairs_jumped, e.pairs_measured), e.reestimated ? "yes" : "no",
         e.reestimated ? std::to_string(e.reestimate_first_frame) : "-",
         e.reestimated ? fmt::format("{:.3f}", e.rms_px) : "-",
         TruthCell(e.truth_rotation_deg, "{:.3f} deg"), e.reason},
        e.reestimated ? "warn" : "bad");
  }
  return fmt::format("<p>{} checks; cameras that moved after the calibration:</p>\n",
                     r.motion_checks) +
         table.ToHtml();
}

std::string HullsSection(const LiveJobResult& r) {
  if (!r.hulls) return "<p class=\"muted\">no hulls</p>\n";
  const HullSequenceResult& h = *r.hulls;
  HtmlTable table({"frame", "file", "method", "closed manifold", "triangles", "volume m^3",
                   "missed (mean over views)", "outside (mean over views)", "note"});
  for (const HullFrameResult& f : h.frames) {
    double missed = 0, spurious = 0;
    for (const ViewReprojection& v : f.views) {
      missed += v.missed_fraction / static_cast<double>(f.views.size());
      spurious += v.spurious_fraction / static_cast<double>(f.views.size());
    }
    table.AddRow({std::to_string(f.frame), f.file, f.method, f.closed_manifold ? "yes" : "no",
                  std::to_string(f.triangles), fmt::format("{:.4g}", f.volume_m3), Percent(missed),
                  Percent(spurious), f.success ? f.polyhedral_failure : f.reason},
                 f.success ? "" : "bad");
  }
  std::string html = fmt::format(
      "<p>{} of {} frames built in {:.1f} s ({}); silhouette pixels the hulls miss: {} on "
      "average, pixels they cover outside the silhouettes: {}. Meshes and hulls.yaml in "
      "<a href=\"hulls/\">hulls/</a>.</p>\n",
      h.Succeeded(), h.frames.size(), h.seconds,
      h.interpolated ? "silhouettes interpolated to common instants" : "nearest frames",
      Percent(h.MeanMissed()), Percent(h.MeanSpurious()));
  return html + table.ToHtml();
}

// The summary's keys, for live_summary.yaml.
void WriteSummary(cv::FileStorage& fs, const LiveJobResult& r) {
  fs << "failure" << r.failure << "seconds" << r.seconds;
  fs << "cameras" << static_cast<int>(r.cameras.size());
  fs << "frames_held" << static_cast<double>(r.ingest.stored) << "frames_missing"
     << static_cast<double>(r.ingest.missing) << "frames_dropped_by_nodes"
     << static_cast<double>(r.ingest.node_dropped) << "frames_flagged_by_nodes"
     << static_cast<double>(r.ingest.node_flagged);
  fs << "calibration_first_frame" << r.calibration_first_frame << "calibration_frames"
     << r.calibration_frames << "calibration_attempts" << r.calibration_attempts << "recalibrations"
     << r.recalibrations << "published" << static_cast<int>(r.published);
  if (r.calibration) {
    const NetworkCalibration& c = r.calibration->calibration;
    fs << "cameras_calibrated" << static_cast<int>(c.PlacedCount()) << "reprojection_rms_px"
       << c.rms_px;
    if (r.calibration->errors) {
      const CalibrationErrors& e = *r.calibration->errors;
      fs << "ground_truth"
         << "{"
         << "median_focal_rel" << e.median_focal_rel << "median_rotation_deg"
         << e.median_rotation_deg << "max_rotation_deg" << e.max_rotation_deg << "median_center_rel"
         << e.median_center_rel << "median_offset_frames" << e.median_offset_frames
         << "max_offset_frames" << e.max_offset_frames << "}";
    }
  }
  fs << "motion_checks" << r.motion_checks;
  WriteMoveEvents(fs, "camera_moves", r.camera_moves);
  if (r.hulls) {
    fs << "hulls"
       << "{"
       << "first_frame" << r.hull_first_frame << "frames"
       << static_cast<int>(r.hulls->frames.size()) << "built"
       << static_cast<int>(r.hulls->Succeeded()) << "mean_missed" << r.hulls->MeanMissed()
       << "mean_spurious" << r.hulls->MeanSpurious() << "}";
  }
  if (r.stills) {
    const StillsStageResult& s = *r.stills;
    fs << "stills"
       << "{"
       << "asked" << static_cast<int>(s.collection.cameras.size()) << "complete"
       << static_cast<int>(s.collection.complete()) << "usable" << static_cast<int>(s.views)
       << "failure" << s.failure;
    if (s.stereo && s.stereo->success) {
      fs << "model_triangles" << static_cast<int>(s.stereo->model.triangles)
         << "model_closed_manifold" << static_cast<int>(s.stereo->model.closed_manifold)
         << "stereo_seconds" << s.stereo->seconds.total;
      if (s.stereo->model.evaluation) {
        fs << "accuracy_footprints" << s.stereo->model.evaluation->accuracy_footprints;
        if (s.stereo->model.evaluation->completeness.size() > 1)
          fs << "completeness_within_2_footprints"
             << s.stereo->model.evaluation->completeness[1].fraction;
      }
    }
    fs << "}";
  }
}

void WriteSummaryYaml(const std::filesystem::path& path, const LiveJobResult& r) {
  ReplaceYaml(path, [&](cv::FileStorage& fs) { WriteSummary(fs, r); });
}

// The stills the nodes sent on command and the stereo model built from them, with its
// pictures and its own report (3D viewer, per-view figures).
std::string StillsSection(const LiveJobResult& r) {
  if (!r.stills) return "<p class=\"muted\">no stills asked for (live --stills)</p>\n";
  const StillsStageResult& s = *r.stills;
  std::string html = fmt::format(
      "<p>{} of {} cameras sent a complete still in {:.1f} s; {} usable for stereo. Stills "
      "folder: <a href=\"stills/stills.yaml\">stills/</a>.</p>\n",
      s.collection.complete(), s.collection.cameras.size(), s.collection.seconds, s.views);
  HtmlTable table({"camera", "still", "frame", "size", "chunks", "corrupt", "asked again"});
  for (const CollectedStill& c : s.collection.cameras) {
    table.AddRow({c.camera_id, c.complete ? "complete" : c.reason,
                  c.complete ? std::to_string(c.frame_index) : "",
                  c.complete ? fmt::format("{}x{}", c.photo.cols, c.photo.rows) : "",
                  std::to_string(c.chunks.accepted), std::to_string(c.chunks.corrupt),
                  std::to_string(c.resend_requests)},
                 c.complete ? "" : "warn");
  }
  html += table.ToHtml();
  if (!s.warnings.empty()) {
    html += "<ul class=\"warn\">";
    for (const std::string& w : s.warnings)
      html += "<li>" + EscapeHtml(w) + "</li>";
    html += "</ul>\n";
  }
  if (s.calibration_vs_truth) {
    html += fmt::format(
        "<p>The calibration in use against the simulation's truth: rotation {:.3f} deg median "
        "({:.3f} max), focal length {:.2f} % median.</p>\n",
        s.calibration_vs_truth->median_rotation_deg, s.calibration_vs_truth->max_rotation_deg,
        100 * s.calibration_vs_truth->median_focal_rel);
  }
  if (!s.stereo || !s.stereo->success) {
    return html + fmt::format("<p class=\"bad\">No stereo model: {}</p>\n", EscapeHtml(s.failure));
  }
  const StereoJobResult& m = *s.stereo;
  html += fmt::format(
      "<p>Stereo model of {} views: {} triangles, {}closed and manifold; silhouette pixels "
      "&ge; 1 px inside missed {} ({} no model consistent with the other views covers), "
      "outside covered {} ({} traded for those of other views); {:.1f} s. Its report, with the "
      "model in 3D: <a href=\"stills/stereo/report.html\">stills/stereo/report.html</a>.</p>\n",
      m.views, m.model.triangles, m.model.closed_manifold ? "" : "not ", m.model.MissedInner(),
      m.model.MissedUncoverable(), m.model.CoveredOuter(), m.model.CoveredOuterTraded(),
      m.seconds.total);
  if (m.model.evaluation && m.hull.evaluation) {
    html += fmt::format("<p>Against the true surface: model {}; visual hull {}.</p>\n",
                        EscapeHtml(m.model.evaluation->Brief()),
                        EscapeHtml(m.hull.evaluation->Brief()));
  }
  if (!s.collection.cameras.empty()) {
    const std::string first = s.collection.cameras.front().camera_id;
    html += fmt::format(
        "<figure><img src=\"stills/stereo/views/{0}.png\" alt=\"{0}\"><figcaption>{0}: the "
        "still, the model seen from that camera, and the silhouette comparison."
        "</figcaption></figure>\n",
        EscapeHtml(first));
  }
  return html;
}

// The hulls to step through in 3D, seen at first as the first placed camera sees them, or why
// they cannot be. The page loads them all: at most kViewerFrames frames, evenly spaced, of at
// most kViewerTriangles triangles each (about 0.3 MB of script per frame).
std::string HullsViewer(const std::filesystem::path& out, const LiveJobResult& r) {
  constexpr size_t kViewerFrames = 40, kViewerTriangles = 10000;
  if (!r.hulls || r.hulls->Succeeded() == 0) return "";
  const std::string missing = InstallMeshViewer(out);
  if (!missing.empty())
    return fmt::format("<p class=\"bad\">No 3D view: {}</p>\n", EscapeHtml(missing));
  std::vector<ViewerLayer> layers;
  try {
    std::vector<const HullFrameResult*> built;
    for (const HullFrameResult& f : r.hulls->frames) {
      if (f.success) built.push_back(&f);
    }
    const size_t step = (built.size() + kViewerFrames - 1) / kViewerFrames;
    for (size_t i = 0; i < built.size(); i += step) {
      const HullFrameResult& f = *built[i];
      const std::string name = fmt::format("hull_{}", f.frame);
      WriteViewerMesh(
          out, name,
          MakeDisplayMesh(ReadPlyMesh((out / "hulls" / f.file).string()), kViewerTriangles));
      layers.push_back({name, fmt::format("frame {}", f.frame), 0x9fc5e8});
    }
  } catch (const std::exception& error) {
    return fmt::format("<p class=\"bad\">No 3D view: {}</p>\n", EscapeHtml(error.what()));
  }
  std::optional<ViewerStart> start;
  if (r.calibration) {
    const NetworkCalibration& c = r.calibration->calibration;
    for (size_t i = 0; i < c.cameras.size() && !start; ++i) {
      if (i < c.placement.size() && !c.placement[i].placed) continue;
      start = ViewerStart{c.cameras[i].Center(),
                          -(c.cameras[i].R.transpose() * Eigen::Vector3d::UnitY())};
    }
  }
  return MeshViewerHtml("hulls-view", layers, start, true);
}

}  // namespace

void WriteLiveReport(const std::filesystem::path& out, const LiveJobResult& result) {
  std::string html;
  if (!result.failure.empty())
    html += "<ul class=\"bad\"><li>" + EscapeHtml(result.failure) + "</li></ul>\n";
  html += Section("Streams", IngestSection(result));
  html += Section("Calibration and synchronisation", CalibrationSection(result));
  html += Section("Moved cameras", MovedCamerasSection(result));
  html += Section("Visual hulls", HullsViewer(out, result) + HullsSection(result));
  html += Section("Stills and stereo model", StillsSection(result));
  WriteHtmlPage(out / "report.html", "silnet live run", html);
  WriteSummaryYaml(out / "live_summary.yaml", result);
}

std::string LiveSummary(const std::filesystem::path& out, const LiveJobResult& r) {
  std::string text = fmt::format("silnet live run: {:.0f} s\n", r.seconds);
  text += fmt::format(
      "  streams      {} cameras, {} frames held, {} missing, {} malformed, {} "
      "duplicates, {} stalls; nodes dropped {}, flagged {}\n",
      r.cameras.size(), r.ingest.stored, r.ingest.missing, r.ingest.malformed, r.ingest.duplicates,
      r.ingest.stalls, r.ingest.node_dropped, r.ingest.node_flagged);
  if (r.calibration) {
    const NetworkCalibration& c = r.calibration->calibration;
    text += fmt::format(
        "  calibration  {} of {} cameras from frames {}..{} (attempt {}, {} recalibrations), "
        "reprojection rms {:.3f} px, {}\n",
        c.PlacedCount(), c.cameras.size(), r.calibration_first_frame,
        r.calibration_first_frame + r.calibration_frames - 1, r.calibration_attempts,
        r.recalibrations, c.rms_px, r.published ? "published" : "not published");
    if (r.calibration->errors) {
      const CalibrationErrors& e = *r.calibration->errors;
      text += fmt::format(
          "  vs truth     focal {:.2f} %, rotation {:.3f} deg (max {:.3f}), centre {:.2f} % of "
          "the rig, offset {:.3f} frames (max {:.3f})\n",
          100 * e.median_focal_rel, e.median_rotation_deg, e.max_rotation_deg,
          100 * e.median_center_rel, e.median_offset_frames, e.max_offset_frames);
    }
  }
  if (r.motion_checks > 0 && r.camera_moves.empty()) {
    text += fmt::format(
        "  motion       {} checks of every pair's epipolar residuals, no camera moved\n",
        r.motion_checks);
  }
  for (const CameraMoveEvent& e : r.camera_moves) {
    text += fmt::format(
        "  MOVED        {} (seen by frame {}): {}\n", e.camera_id, e.detected_frame,
        e.reestimated
            ? fmt::format("re-estimated from frame {}, {:.3f} px rms{}", e.reestimate_first_frame,
                          e.rms_px,
                          e.truth_rotation_deg < 0.0
                              ? ""
                              : fmt::format(", rotation vs truth {:.3f} deg", e.truth_rotation_deg))
            : "not re-estimated: " + e.reason);
  }
  if (r.hulls) {
    text += fmt::format(
        "  hulls        {} of {} frames from frame {}, {}closed, silhouette pixels missed {:.2f} "
        "%, covered outside {:.2f} %\n",
        r.hulls->Succeeded(), r.hulls->frames.size(), r.hull_first_frame,
        r.hulls->AllClosedManifold() ? "all " : "not all ", 100 * r.hulls->MeanMissed(),
        100 * r.hulls->MeanSpurious());
  }
  if (r.stills) text += StillsSummary(*r.stills);
  if (!r.failure.empty()) text += "  FAILED       " + r.failure + "\n";
  text += fmt::format("  report       {}\n", (out / "report.html").string());
  return text;
}

std::string StillsSummary(const StillsStageResult& s) {
  std::string text = fmt::format("  stills       {} of {} cameras, {} usable\n",
                                 s.collection.complete(), s.collection.cameras.size(), s.views);
  if (s.stereo && s.stereo->success) {
    text += fmt::format(
        "  stereo       {} triangles, {}closed, {:.1f} s{}\n", s.stereo->model.triangles,
        s.stereo->model.closed_manifold ? "" : "not ", s.stereo->seconds.total,
        s.stereo->model.evaluation ? "; vs truth " + s.stereo->model.evaluation->Brief()
                                   : std::string());
  }
  if (!s.failure.empty()) text += fmt::format("  no model     {}\n", s.failure);
  return text;
}

}  // namespace silnet::aggregator
