#include "shared/dds/sample_conversions.h"

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

void ToWire(const CameraInfoRecord& info, silnet_wire_CameraInfo* sample,
            std::vector<silnet_wire_Parameter>* storage) {
  *sample = silnet_wire_CameraInfo{};
  CopyBoundedString(info.camera_id, sample->camera_id, "camera id");
  sample->session = info.session;
  CopyBoundedString(info.host.substr(0, 63), sample->host, "host");
  CopyBoundedString(info.node_version, sample->node_version, "node version");
  CopyBoundedString(info.source_kind, sample->source_kind, "source kind");
  sample->image_width = info.width;
  sample->image_height = info.height;
  sample->nominal_fps = info.nominal_fps;
  CopyBoundedString(info.segmentation, sample->segmentation, "segmentation");
  storage->clear();
  for (const auto& [name, value] : info.parameters) {
    silnet_wire_Parameter p{};
    CopyBoundedString(name, p.name, "parameter name");
    CopyBoundedString(value, p.value, "parameter value");
    storage->push_back(p);
  }
  sample->parameters._buffer = storage->data();
  sample->parameters._length = static_cast<uint32_t>(storage->size());
  sample->parameters._maximum = sample->parameters._length;
  sample->parameters._release = false;
}

CameraInfoRecord FromWire(const silnet_wire_CameraInfo& sample) {
  CameraInfoRecord info;
  info.camera_id = ReadBoundedString(sample.camera_id);
  info.session = sample.session;
  info.host = ReadBoundedString(sample.host);
  info.node_version = ReadBoundedString(sample.node_version);
  info.source_kind = ReadBoundedString(sample.source_kind);
  info.width = sample.image_width;
  info.height = sample.image_height;
  info.nominal_fps = sample.nominal_fps;
  info.segmentation = ReadBoundedString(sample.segmentation);
  for (uint32_t i = 0; i < sample.parameters._length && sample.parameters._buffer != nullptr; ++i) {
    info.parameters[ReadBoundedString(sample.parameters._buffer[i].name)] =
        ReadBoundedString(sample.parameters._buffer[i].value);
  }
  return info;
}

silnet_wire_Calibration ToWire(const CameraModel& camera, uint64_t calibration_id,
                               double time_offset_sigma, double reprojection_error_px) {
  silnet_wire_Calibration sample{};
  CopyBoundedString(camera.id, sample.camera_id, "camera id");
  sample.calibration_id = calibration_id;
  sample.image_width = static_cast<uint16_t>(camera.width);
  sample.image_height = static_cast<uint16_t>(camera.height);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      sample.K[3 * r + c] = camera.K(r, c);
      sample.R[3 * r + c] = camera.R(r, c);
    }
    sample.t[r] = camera.t[r];
  }
  for (int k = 0; k < 5; ++k)
    sample.dist[k] = camera.dist[k];
  sample.fps = camera.fps;
  sample.time_offset = camera.time_offset;
  sample.time_offset_sigma = time_offset_sigma;
  sample.reprojection_error_px = reprojection_error_px;
  return sample;
}

CameraModel FromWire(const silnet_wire_Calibration& sample) {
  CameraModel camera;
  camera.id = ReadBoundedString(sample.camera_id);
  camera.width = sample.image_width;
  camera.height = sample.image_height;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      camera.K(r, c) = sample.K[3 * r + c];
      camera.R(r, c) = sample.R[3 * r + c];
    }
    camera.t[r] = sample.t[r];
  }
  for (int k = 0; k < 5; ++k)
    camera.dist[k] = sample.dist[k];
  camera.fps = sample.fps;
  camera.time_offset = sample.time_offset;
  return camera;
}

}  // namespace silnet::dds
