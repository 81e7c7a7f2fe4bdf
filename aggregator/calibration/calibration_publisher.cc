#include "aggregator/calibration/calibration_publisher.h"

#include "shared/dds/sample_conversions.h"

namespace silnet::aggregator {

CalibrationPublisher::CalibrationPublisher(const dds::Participant& participant)
    : topic_(participant), writer_(topic_) {}

size_t CalibrationPublisher::Publish(const NetworkCalibration& calibration,
                                     uint64_t calibration_id) {
  size_t written = 0;
  for (size_t c = 0; c < calibration.cameras.size(); ++c) {
    if (!calibration.placement[c].placed) continue;
    const double sigma = c < calibration.sync.sigmas.size() ? calibration.sync.sigmas[c] : 0.0;
    const silnet_wire_Calibration sample =
        dds::ToWire(calibration.cameras[c], calibration_id, sigma, calibration.placement[c].rms_px);
    written += writer_.Write(sample) ? 1 : 0;
  }
  return written;
}

uint64_t NewCalibrationId() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count());
}

}  // namespace silnet::aggregator
