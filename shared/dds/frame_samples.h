#pragma once
// Conversions between FrameRecord and the HullFrame / Contour wire samples.

#include "shared/dds/topics.h"
#include "shared/io/frame_record.h"

namespace silnet::dds {

// Fills a wire sample from a record. The sample's payload sequence borrows the record's
// payload buffer (no copy): keep `record` alive and unchanged until the sample is written.
// Throws InputError if the camera id is too long for the wire type.
void ToWire(const FrameRecord& record, silnet_wire_HullFrame* sample);
void ToWire(const FrameRecord& record, silnet_wire_Contour* sample);

// Copies a received wire sample into a record.
FrameRecord FromWire(const silnet_wire_HullFrame& sample);
FrameRecord FromWire(const silnet_wire_Contour& sample);

}  // namespace silnet::dds
