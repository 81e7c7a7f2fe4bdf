#include "aggregator/report/calibration_report.h"

#include <fmt/format.h>

#include <fstream>
#include <string>

#include "aggregator/report/error_histogram_plot.h"
#include "aggregator/report/html_table.h"
#include "aggregator/report/network_plot.h"
#include "aggregator/report/offset_graph_plot.h"
#include "aggregator/report/report_sections.h"
#include "shared/io/png_writer.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 2em; color: #222; max-width: 1500px; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #f0f0f0; }
tr.bad td { background: #fde8e8; }
tr.warn td { background: #fff6da; }
ul.bad { color: #a00; }
.muted { color: #777; }
img { max-width: 100%; border: 1px solid #ddd; margin: 0.3em 0; }
)";

void CreateFolder(const std::filesystem::path& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    throw InputError(
        fmt::format("cannot create report folder '{}': {}", dir.string(), error.message()));
  }
}

std::string Section(const std::string& title, const std::string& body) {
  return "<h2>" + EscapeHtml(title) + "</h2>\n" + body;
}

std::string Figure(const std::string& file, const std::string& caption) {
  return "<figure><img src=\"plots/" + EscapeHtml(file) + "\" alt=\"" + EscapeHtml(caption) +
         "\"><figcaption>" + EscapeHtml(caption) + "</figcaption></figure>\n";
}

}  // namespace

void WriteCalibrationReport(const std::filesystem::path& dir, const NetworkCalibration& calibration,
                            const std::optional<CalibrationErrors>& errors) {
  CreateFolder(dir / "plots");
  WritePngFast(dir / "plots" / "camera_network.png", DrawCameraNetwork(calibration));
  WritePngFast(dir / "plots" / "reprojection_errors.png", DrawErrorHistograms(calibration));
  WritePngFast(dir / "plots" / "offsets_graph.png", DrawOffsetGraph(calibration));

  std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<title>silnet calibration report</title>\n<style>" + std::string(kStyle) +
          "</style>\n</head>\n<body>\n<h1>silnet calibration report</h1>\n";
  html += Section("Summary", SummarySection(calibration));
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
  html += Section("Pairwise checks", PairChecksSection(calibration));
  if (errors.has_value()) html += Section("Ground truth", GroundTruthSection(*errors));
  html += "</body>\n</html>\n";

  const std::filesystem::path path = dir / "report.html";
  std::ofstream out(path, std::ios::binary);
  out << html;
  out.flush();
  if (!out) throw InputError(fmt::format("cannot write report '{}'", path.string()));
}

}  // namespace silnet::aggregator
