#pragma once
// What the live job reports: OUT/report.html (ingest per camera, the calibration with its
// plots from calibration/report/, ground-truth errors when known, the hulls with their
// reprojection figures and overlays), OUT/live_summary.yaml with the headline figures, and
// the one-screen summary printed at the end.

#include <filesystem>
#include <string>

#include "aggregator/live/live_job.h"

namespace silnet::aggregator {

// Writes OUT/report.html and OUT/live_summary.yaml. Throws InputError if unwritable.
void WriteLiveReport(const std::filesystem::path& out, const LiveJobResult& result);

// The summary for the console: a few lines per stage, errors against ground truth when
// known, where the files are.
std::string LiveSummary(const std::filesystem::path& out, const LiveJobResult& result);

// The stills and stereo lines of that summary: how many cameras answered, the model and its
// errors against the truth when known, and why there is no model if there is none.
std::string StillsSummary(const StillsStageResult& stills);

}  // namespace silnet::aggregator
