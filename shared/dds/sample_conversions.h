#pragma once
// Conversions between silnet's DDS-independent records and the wire samples.

#include <vector>

#include "shared/dds/topics.h"
#include "shared/geometry/camera_model.h"
#include "shared/io/frame_record.h"
#include "shared/io/session_log.h"

namespace silnet::dds {

// Fills a wire sample from a record. The sample's payload sequence borrows the record's
// payload buffer (no copy): keep `record` alive and unchanged until the sample is written.
// Throws InputError if the camera id is too long for the wire type.
void ToWire(const FrameRecord& record, silnet_wire_HullFrame* sample);
void ToWire(const FrameRecord& record, silnet_wire_Contour* sample);

// Copies a received wire sample into a record.
FrameRecord FromWire(const silnet_wire_HullFrame& sample);
FrameRecord FromWire(const silnet_wire_Contour& sample);

// Fills a CameraInfo sample; its parameter sequence borrows `storage` (keep it alive until
// the sample is written). Throws InputError if a field is too long for the wire type.
void ToWire(const CameraInfoRecord& info, silnet_wire_CameraInfo* sample,
            std::vector<silnet_wire_Parameter>* storage);
CameraInfoRecord FromWire(const silnet_wire_CameraInfo& sample);

// A camera's calibration as the Calibration sample (and back). `calibration_id` names the
// calibration run; sigma and error describe its quality.
silnet_wire_Calibration ToWire(const CameraModel& camera, uint64_t calibration_id,
                               double time_offset_sigma, double reprojection_error_px);
CameraModel FromWire(const silnet_wire_Calibration& sample);

}  // namespace silnet::dds
