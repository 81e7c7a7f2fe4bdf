#pragma once
// The stereo job's report: one self-contained HTML page (OUT/report.html) for people to look
// at. What the job made or why it made nothing; the model and the hull to turn in 3D
// (mesh_viewer.h, three.js copied beside the page); the model beside the visual hull (size,
// silhouette consistency, accuracy and completeness against the truth when there is one);
// time per stage; the graph cut's figures and silhouette steps; then per view its figures and
// the picture the job drew (photo | model shaded from that camera | silhouette comparison).

#include "aggregator/stereo/stereo_job.h"

namespace silnet::aggregator {

// Writes config.output/report.html for `result`, linking result.view_pictures relatively (the
// folder can be moved as a whole). All text from the input (camera ids, warnings, reasons) is
// HTML-escaped. Also written for a failed run, with its reason first. Throws InputError
// naming the path if it cannot be written.
void WriteStereoReport(const StereoJobConfig& config, const StereoJobResult& result);

}  // namespace silnet::aggregator
