#pragma once
// A NetworkCalibration built from a simulated camera network for the report and export
// tests: placed cameras are the ground truth, frontier points are random 3D points seen by
// two placed cameras with known pixel noise, and the synchronisation and pair checks are
// made up around the true offsets (one rejected edge, one corrected pair).

#include <Eigen/Core>
#include <cstdint>
#include <set>
#include <vector>

#include "aggregator/calibration/calibration_result.h"
#include "sim/camera_network.h"

namespace silnet::aggregator::testing {

struct TestNetworkOptions {
  sim::CameraNetworkOptions network;  // defaults: 8 cameras in a ring
  std::set<size_t> unplaced = {5};    // cameras left unplaced (with a reason)
  int points = 400;                   // frontier points
  double outlier_fraction = 0.1;      // points marked as outliers (pixel error 5-20 px)
  double pixel_noise = 0.3;           // standard deviation of the observed pixels
  uint64_t seed = 7;
};

// The calibration; every observation's error_px is the exact distance between the observed
// pixel and the camera's projection of the point.
NetworkCalibration MakeTestCalibration(const TestNetworkOptions& options = {});

}  // namespace silnet::aggregator::testing
