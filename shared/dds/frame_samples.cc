#include "shared/dds/frame_samples.h"

namespace silnet::dds {
namespace {

template <class Sample>
void FillHeader(const FrameRecord& record, Sample* sample) {
  *sample = Sample{};
  CopyBoundedString(record.camera_id, sample->camera_id, "camera id");
  sample->session = record.session;
  sample->frame_index = record.frame_index;
  sample->capture_time_ns = record.capture_time_ns;
  sample->image_width = record.width;
  sample->image_height = record.height;
  sample->flags = record.flags;
}

void Borrow(const std::vector<uint8_t>& payload, dds_sequence_octet* sequence) {
  sequence->_buffer = const_cast<uint8_t*>(payload.data());
  sequence->_length = static_cast<uint32_t>(payload.size());
  sequence->_maximum = sequence->_length;
  sequence->_release = false;
}

template <class Sample>
FrameRecord ReadHeader(const Sample& sample) {
  FrameRecord record;
  record.camera_id = ReadBoundedString(sample.camera_id);
  record.session = sample.session;
  record.frame_index = sample.frame_index;
  record.capture_time_ns = sample.capture_time_ns;
  record.width = sample.image_width;
  record.height = sample.image_height;
  record.flags = sample.flags;
  return record;
}

}  // namespace

void ToWire(const FrameRecord& record, silnet_wire_HullFrame* sample) {
  FillHeader(record, sample);
  Borrow(record.payload, &sample->hull);
}

void ToWire(const FrameRecord& record, silnet_wire_Contour* sample) {
  FillHeader(record, sample);
  Borrow(record.payload, &sample->polygons);
}

FrameRecord FromWire(const silnet_wire_HullFrame& sample) {
  FrameRecord record = ReadHeader(sample);
  if (sample.hull._buffer != nullptr) {
    record.payload.assign(sample.hull._buffer, sample.hull._buffer + sample.hull._length);
  }
  return record;
}

FrameRecord FromWire(const silnet_wire_Contour& sample) {
  FrameRecord record = ReadHeader(sample);
  if (sample.polygons._buffer != nullptr) {
    record.payload.assign(sample.polygons._buffer,
                          sample.polygons._buffer + sample.polygons._length);
  }
  return record;
}

}  // namespace silnet::dds
