#include "aggregator/report/calibration_report.h"

#include <fmt/format.h>

#include <string>

#include "aggregator/calibration/motion_coverage.h"
#include "aggregator/report/error_histogram_plot.h"
#include "aggregator/report/html_table.h"
#include "aggregator/report/network_plot.h"
#include "aggregator/report/offset_graph_plot.h"
#include "aggregator/report/report_sections.h"
#include "shared/io/png_writer.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

void CreateFolder(const std::filesystem::path& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    throw InputError(
        fmt::format("cannot create report folder '{}': {}", dir.string(), error.message()));
  }
}

std::string Figure(const std::string& file, const std::string& caption) {
  return "<figure><img src=\"plots/" + EscapeHtml(file) + "\" alt=\"" + EscapeHtml(caption) +
         "\"><figcaption>" + EscapeHtml(caption) + "</figcaption></figure>\n";
}

// One picture per camera of where its silhouettes went, and what each camera lacks.
std::string MotionSection(const std::filesystem::path& dir, const NetworkCalibration& calibration) {
  std::string html =
      "<p>Where each camera's silhouettes went during the capture (brighter: more often). "
      "Calibration needs them to sweep the image and move in many directions.</p>\n";
  for (const MotionCoverage& m : calibration.motion) {
    if (m.frames == 0) continue;
    const std::string file = "motion_" + m.camera_id + ".png";
    WritePngFast(dir / "plots" / file, DrawMotionCoverage(m));
    html += Figure(file, m.camera_id + ": " + m.Describe() + (m.sufficient ? "" : ". " + m.advice));
  }
  return html;
}

}  // namespace

void WriteCalibrationReport(const std::filesystem::path& dir, const NetworkCalibration& calibration,
                            const std::optional<CalibrationErrors>& errors) {
  CreateFolder(dir / "plots");
  WritePngFast(dir / "plots" / "camera_network.png", DrawCameraNetwork(calibration));
  WritePngFast(dir / "plots" / "reprojection_errors.png", DrawErrorHistograms(calibration));
  WritePngFast(dir / "plots" / "offsets_graph.png", DrawOffsetGraph(calibration));

  std::string html = Section("Summary", SummarySection(calibration));
  html += Section("Stages", StagesSection(calibration));
  html += Section("Camera network",
                  Figure("camera_network.png",
                         "Placed cameras and inlier frontier points, orthographic views from "
                         "above and from the side (the thick edge of each pyramid is the top "
                         "of its image)."));
  html += Section(
      "Cameras", CamerasSection(calibration) + Figure("reprojection_errors.png",
                                                      "Reprojection errors of each camera's inlier "
                                                      "observations (red line: median)."));
  html += Section("Synchronisation",
                  Figure("offsets_graph.png",
                         "Time offsets (frames) and pairwise offset measurements; residual "
                         "labels are in frames.") +
                      SyncEdgesSection(calibration));
  if (!calibration.motion.empty()) html += Section("Motion", MotionSection(dir, calibration));
  html += Section("Pairwise checks", PairChecksSection(calibration));
  if (errors.has_value()) html += Section("Ground truth", GroundTruthSection(*errors));
  WriteHtmlPage(dir / "report.html", "silnet calibration report", html);
}

}  // namespace silnet::aggregator
