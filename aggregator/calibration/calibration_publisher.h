#pragma once
// Publishes a network calibration on the latched Calibration topic (DESIGN.md "Wire
// types"): one sample per calibrated camera, kept by the writer for nodes and tools that join
// later, for as long as the publisher lives.

#include <chrono>
#include <cstdint>

#include "aggregator/calibration/calibration_result.h"
#include "shared/dds/participant.h"
#include "shared/dds/topic.h"
#include "shared/dds/topics.h"

namespace silnet::aggregator {

// The aggregator's Calibration writer.
class CalibrationPublisher {
 public:
  explicit CalibrationPublisher(const dds::Participant& participant);

  // Writes every placed camera with `calibration_id` (larger for newer runs) and returns how
  // many samples were written. Throws DdsError if DDS fails.
  size_t Publish(const NetworkCalibration& calibration, uint64_t calibration_id);
  // Blocks until `count` readers matched or the timeout passed; returns whether they did.
  bool WaitForReaders(uint32_t count, std::chrono::milliseconds timeout) const {
    return writer_.WaitForReaders(count, timeout);
  }

 private:
  dds::Topic<silnet_wire_Calibration> topic_;
  dds::Writer<silnet_wire_Calibration> writer_;
};

// A calibration id that grows with time: milliseconds since the Unix epoch.
uint64_t NewCalibrationId();

}  // namespace silnet::aggregator
