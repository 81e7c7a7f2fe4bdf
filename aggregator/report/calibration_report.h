#pragma once
// The calibration report: one self-contained HTML page (report.html) with PNG plots under
// plots/: the camera network in 3D from above and from the side with the frontier points,
// a reprojection-error histogram per camera, and the offsets graph with each edge's
// residual; tables of cameras, stages, synchronisation edges and pairwise checks.

#include <filesystem>
#include <optional>

#include "aggregator/calibration/calibration_result.h"
#include "aggregator/calibration/ground_truth_comparison.h"

namespace silnet::aggregator {

// Writes <dir>/report.html and <dir>/plots/{camera_network,reprojection_errors,
// offsets_graph}.png, and motion_<camera>.png per camera when the calibration measured the
// silhouettes' motion (creating the folders; the page links the plots relatively, so the
// folder can be moved as a whole). All text from the calibration (ids, reasons, notes) is
// HTML-escaped. Unplaced cameras appear in the tables with their reason, not in the 3D
// view. `errors` adds a section comparing with ground truth. Throws InputError naming the
// path if the folder or a file is unwritable.
void WriteCalibrationReport(const std::filesystem::path& dir, const NetworkCalibration& calibration,
                            const std::optional<CalibrationErrors>& errors = std::nullopt);

}  // namespace silnet::aggregator
