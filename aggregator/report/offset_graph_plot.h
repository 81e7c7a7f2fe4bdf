#pragma once
// The offsets graph of the network synchronisation (thesis 3.3): cameras as nodes on a
// circle labelled with their id and time offset (± sigma), the pairwise offset measurements
// as edges, solid and coloured by |residual| / sigma when used, dashed red when rejected,
// with the residual (frames) written on each edge where there is room.

#include <opencv2/core.hpp>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// The graph as a size x size BGR image.
cv::Mat DrawOffsetGraph(const NetworkCalibration& calibration, int size = 900);

}  // namespace silnet::aggregator
