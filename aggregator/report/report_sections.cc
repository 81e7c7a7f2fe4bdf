#include "aggregator/report/report_sections.h"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "aggregator/report/html_table.h"
#include "aggregator/report/report_statistics.h"

namespace silnet::aggregator {
namespace {

const char* const kNone = "\u2014";  // em dash for "no value"

std::string Fixed(double value, int digits) {
  return fmt::format("{:.{}f}", value, digits);
}

std::string YesNo(bool value) {
  return value ? "yes" : "no";
}

// "o ± sigma" from the synchronisation, or why there is none.
std::string TimeOffset(const NetworkCalibration& calibration, size_t i) {
  const SyncResult& sync = calibration.sync;
  if (i < sync.synchronised.size() && !sync.synchronised[i]) {
    const std::string reason = i < sync.reasons.size() ? sync.reasons[i] : std::string();
    return reason.empty() ? "not synchronised" : "not synchronised: " + reason;
  }
  if (i < sync.offsets.size()) {
    const double sigma = i < sync.sigmas.size() ? sync.sigmas[i] : 0.0;
    return fmt::format("{:+.3f} \u00b1 {:.3f}", sync.offsets[i], sigma);
  }
  if (IsPlaced(calibration, i)) return fmt::format("{:+.3f}", calibration.cameras[i].time_offset);
  return kNone;
}

}  // namespace

std::string SummarySection(const NetworkCalibration& calibration) {
  size_t inliers = 0;
  for (const FrontierPoint& p : calibration.points)
    inliers += p.inlier ? 1 : 0;
  size_t edges_used = 0, pairs_used = 0, pairs_corrected = 0;
  for (const SyncEdgeResult& e : calibration.sync.edges)
    edges_used += e.used ? 1 : 0;
  for (const PairCheck& p : calibration.pairs) {
    pairs_used += p.used ? 1 : 0;
    pairs_corrected += p.corrected ? 1 : 0;
  }
  HtmlTable table(std::vector<std::string>{});
  table.AddRow({"cameras placed",
                fmt::format("{} of {}", calibration.PlacedCount(), calibration.cameras.size())});
  table.AddRow(
      {"final reprojection error",
       fmt::format("rms {:.3f} px, median {:.3f} px", calibration.rms_px, calibration.median_px)});
  table.AddRow({"intrinsics",
                calibration.known_intrinsics ? "known (given by the user)" : "self-calibrated"});
  table.AddRow(
      {"frontier points", fmt::format("{} ({} inliers)", calibration.points.size(), inliers)});
  table.AddRow({"synchronisation",
                fmt::format("reference {}, {} of {} offset edges used, rms residual {:.3f} "
                            "frames ({:.2f} sigma)",
                            calibration.cameras.empty()
                                ? std::string(kNone)
                                : CameraLabel(calibration, calibration.sync.reference),
                            edges_used, calibration.sync.edges.size(),
                            calibration.sync.rms_residual, calibration.sync.rms_normalised)});
  table.AddRow({"pairs", fmt::format("{} checked, {} used, {} corrected", calibration.pairs.size(),
                                     pairs_used, pairs_corrected)});
  std::string html = table.ToHtml();
  std::string unplaced;
  for (size_t i = 0; i < calibration.cameras.size(); ++i) {
    if (IsPlaced(calibration, i)) continue;
    const std::string reason =
        i < calibration.placement.size() ? calibration.placement[i].reason : std::string();
    unplaced += "<li>" + EscapeHtml(calibration.cameras[i].id) + ": " +
                EscapeHtml(reason.empty() ? "no reason given" : reason) + "</li>\n";
  }
  if (!unplaced.empty()) html += "<p>Not placed:</p>\n<ul class=\"bad\">\n" + unplaced + "</ul>\n";
  return html;
}

std::string StagesSection(const NetworkCalibration& calibration) {
  HtmlTable table({"stage", "rms (px)", "time (s)", "detail"});
  for (const CalibrationStage& s : calibration.stages)
    table.AddRow({s.name, Fixed(s.rms_px, 3), Fixed(s.seconds, 2), s.detail});
  return table.ToHtml("no stages recorded");
}

std::string CamerasSection(const NetworkCalibration& calibration) {
  HtmlTable table({"id", "placed", "added by", "fx", "fy", "principal point", "k1", "k2", "centre",
                   "time offset (frames)", "observations", "rms (px)", "median (px)",
                   "rotation sigma (deg)", "centre sigma (% rig)", "focal sigma (%)",
                   "pp sigma (px)"});
  for (size_t i = 0; i < calibration.cameras.size(); ++i) {
    const CameraModel& c = calibration.cameras[i];
    const CameraPlacement placement =
        i < calibration.placement.size() ? calibration.placement[i] : CameraPlacement{};
    if (!IsPlaced(calibration, i)) {
      table.AddRow(
          {c.id, "no: " + (placement.reason.empty() ? "no reason given" : placement.reason), kNone,
           kNone, kNone, kNone, kNone, kNone, kNone, TimeOffset(calibration, i), kNone, kNone,
           kNone, kNone, kNone, kNone, kNone},
          "bad");
      continue;
    }
    const Eigen::Vector3d centre = c.Center();
    const CameraUncertainty& u = placement.uncertainty;
    table.AddRow({c.id, "yes", placement.added_by, Fixed(c.K(0, 0), 1), Fixed(c.K(1, 1), 1),
                  fmt::format("({:.1f}, {:.1f})", c.K(0, 2), c.K(1, 2)), Fixed(c.dist[0], 4),
                  Fixed(c.dist[1], 4),
                  fmt::format("({:.3f}, {:.3f}, {:.3f})", centre.x(), centre.y(), centre.z()),
                  TimeOffset(calibration, i), std::to_string(placement.observations),
                  Fixed(placement.rms_px, 3), Fixed(placement.median_px, 3),
                  u.estimated ? Fixed(u.rotation_deg, 3) : kNone,
                  u.estimated ? Fixed(100.0 * u.center_rel, 3) : kNone,
                  u.estimated ? Fixed(100.0 * u.focal_rel, 3) : kNone,
                  u.estimated ? Fixed(u.principal_px, 2) : kNone});
  }
  return table.ToHtml("no cameras");
}

std::string SyncEdgesSection(const NetworkCalibration& calibration) {
  HtmlTable table({"i", "j", "measured (frames)", "sigma", "residual", "residual / sigma", "used",
                   "cycles failed / total"});
  for (const SyncEdgeResult& e : calibration.sync.edges) {
    const double normalised = e.edge.sigma > 0.0 ? e.residual / e.edge.sigma : 0.0;
    table.AddRow({CameraLabel(calibration, e.edge.i), CameraLabel(calibration, e.edge.j),
                  fmt::format("{:+.3f}", e.edge.offset), Fixed(e.edge.sigma, 3),
                  fmt::format("{:+.3f}", e.residual), fmt::format("{:+.2f}", normalised),
                  e.used ? "yes" : "no: " + (e.rejection.empty() ? "rejected" : e.rejection),
                  fmt::format("{} / {}", e.cycles_failed, e.cycles)},
                 e.used ? "" : "bad");
  }
  return table.ToHtml("no offset measurements");
}

std::string PairChecksSection(const NetworkCalibration& calibration) {
  HtmlTable table({"pair", "pairwise", "used", "Zhang distance (px)", "corrected", "note"});
  for (const PairCheck& p : calibration.pairs) {
    std::string status = ToString(p.pairwise_status);
    if (!p.pairwise_reason.empty()) status += ": " + p.pairwise_reason;
    table.AddRow({CameraLabel(calibration, p.i) + " \u2013 " + CameraLabel(calibration, p.j),
                  status, YesNo(p.used), p.distance_px < 0.0 ? kNone : Fixed(p.distance_px, 2),
                  YesNo(p.corrected), p.note},
                 p.corrected ? "warn" : "");
  }
  return table.ToHtml("no pairs checked");
}

std::string GroundTruthSection(const CalibrationErrors& e) {
  HtmlTable summary({"quantity", "median", "maximum"});
  summary.AddRow({"focal length error (%)", Fixed(100.0 * e.median_focal_rel, 3),
                  Fixed(100.0 * e.max_focal_rel, 3)});
  summary.AddRow(
      {"rotation error (degrees)", Fixed(e.median_rotation_deg, 3), Fixed(e.max_rotation_deg, 3)});
  summary.AddRow({"centre error (% of rig diameter)", Fixed(100.0 * e.median_center_rel, 3),
                  Fixed(100.0 * e.max_center_rel, 3)});
  summary.AddRow({"time offset error (frames)", Fixed(e.median_offset_frames, 4),
                  Fixed(e.max_offset_frames, 4)});
  summary.AddRow({"k1 error", Fixed(e.median_k1_error, 5), kNone});
  HtmlTable cameras({"id", "focal (%)", "rotation (deg)", "centre (%)", "principal point (px)",
                     "k1 error", "offset (frames)"});
  for (const CameraError& c : e.cameras) {
    cameras.AddRow({c.id, Fixed(100.0 * c.focal_rel, 3), Fixed(c.rotation_deg, 3),
                    Fixed(100.0 * c.center_rel, 3), Fixed(c.principal_px, 2), Fixed(c.k1_error, 5),
                    Fixed(c.offset_frames, 4)});
  }
  return fmt::format("<p>{} cameras compared; rig diameter {:.3f} (ground-truth units).</p>\n",
                     e.cameras.size(), e.rig_diameter) +
         summary.ToHtml() + cameras.ToHtml("no cameras compared");
}

}  // namespace silnet::aggregator
