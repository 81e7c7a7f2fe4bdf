#include "node/publish/node_transport.h"

#include <spdlog/spdlog.h>

#include "shared/util/crc32.h"

namespace silnet::node {

NodeTransport::NodeTransport(const dds::DomainConfig& domain, std::string camera_id,
                             const dds::QosSettings& qos)
    : camera_id_(std::move(camera_id)),
      participant_(domain),
      hull_topic_(participant_),
      contour_topic_(participant_),
      info_topic_(participant_),
      status_topic_(participant_),
      still_topic_(participant_),
      command_topic_(participant_),
      hull_writer_(hull_topic_, qos),
      contour_writer_(contour_topic_, qos),
      info_writer_(info_topic_, qos),
      status_writer_(status_topic_, qos),
      still_writer_(still_topic_, qos),
      command_reader_(command_topic_, qos) {}

template <class Sample>
bool NodeTransport::WriteRetrying(dds::Writer<Sample>& writer, const Sample& sample,
                                  const std::atomic<bool>& stop) {
  while (!writer.Write(sample)) {
    ++write_timeouts_;
    if (stop.load()) return false;
  }
  return true;
}

bool NodeTransport::PublishHull(const FrameRecord& record, const std::atomic<bool>& stop) {
  silnet_wire_HullFrame sample;
  dds::ToWire(record, &sample);
  return WriteRetrying(hull_writer_, sample, stop);
}

bool NodeTransport::PublishContour(const FrameRecord& record, const std::atomic<bool>& stop) {
  silnet_wire_Contour sample;
  dds::ToWire(record, &sample);
  return WriteRetrying(contour_writer_, sample, stop);
}

void NodeTransport::PublishCameraInfo(const CameraInfoRecord& info) {
  silnet_wire_CameraInfo sample;
  std::vector<silnet_wire_Parameter> storage;
  dds::ToWire(info, &sample, &storage);
  if (!info_writer_.Write(sample)) spdlog::warn("camera info write timed out");
}

void NodeTransport::PublishStatus(const silnet_wire_NodeStatus& status) {
  if (!status_writer_.Write(status)) spdlog::debug("status write timed out");
}

size_t NodeTransport::PublishStillChunks(const EncodedStill& still, silnet_wire_StillPart part,
                                         uint32_t first, uint32_t last, size_t chunk_bytes,
                                         const StillChunkFaults& faults,
                                         const std::atomic<bool>& stop) {
  const std::vector<uint8_t>& data =
      part == silnet_wire_STILL_PHOTO ? still.photo : still.silhouette;
  chunk_bytes = std::max<size_t>(chunk_bytes, 1);
  const size_t chunks = std::max<size_t>(1, (data.size() + chunk_bytes - 1) / chunk_bytes);
  // What every chunk of this part says about the image.
  silnet_wire_Still sample{};
  dds::CopyBoundedString(camera_id_, sample.camera_id, "camera id");
  sample.still_id = still.still_id;
  sample.part = part;
  sample.chunk_count = static_cast<uint32_t>(chunks);
  sample.frame_index = still.frame_index;
  sample.frame_flags = still.frame_flags;
  sample.capture_time_ns = still.capture_time_ns;
  sample.image_width = static_cast<uint16_t>(still.width);
  sample.image_height = static_cast<uint16_t>(still.height);
  dds::CopyBoundedString(part == silnet_wire_STILL_PHOTO ? still.photo_encoding : "png",
                         sample.encoding, "encoding");
  sample.image_bytes = data.size();
  sample.image_crc32 = Crc32(0, data.data(), data.size());
  size_t written = 0;
  for (size_t i = first; i < chunks && i <= last; ++i) {
    if (static_cast<int>(i) == faults.drop_chunk) continue;
    const size_t begin = i * chunk_bytes, end = std::min(data.size(), begin + chunk_bytes);
    sample.chunk_index = static_cast<uint32_t>(i);
    sample.chunk_crc32 = Crc32(0, data.data() + begin, end - begin);
    // The writer only reads the data; a chunk to corrupt (tests) is a spoilt copy.
    std::vector<uint8_t> spoilt;
    const uint8_t* bytes = data.data() + begin;
    if (static_cast<int>(i) == faults.corrupt_chunk && end > begin) {
      spoilt.assign(bytes, bytes + (end - begin));
      spoilt[spoilt.size() / 2] ^= 0x5a;
      bytes = spoilt.data();
    }
    sample.data._buffer = const_cast<uint8_t*>(bytes);
    sample.data._length = static_cast<uint32_t>(end - begin);
    sample.data._maximum = sample.data._length;
    sample.data._release = false;
    if (!WriteRetrying(still_writer_, sample, stop)) break;
    ++written;
  }
  return written;
}

std::vector<silnet_wire_Command> NodeTransport::TakeCommands(std::chrono::milliseconds wait) {
  std::vector<silnet_wire_Command> commands;
  command_reader_.WaitForData(wait);
  command_reader_.Take([&](const silnet_wire_Command& command, const dds_sample_info_t&) {
    const std::string target = dds::ReadBoundedString(command.target);
    if (target == "*" || target == camera_id_) commands.push_back(command);
  });
  return commands;
}

bool NodeTransport::WaitForAcknowledgements(std::chrono::milliseconds timeout) {
  return hull_writer_.WaitForAcknowledgements(timeout) &&
         contour_writer_.WaitForAcknowledgements(timeout);
}

TransportCounters NodeTransport::Counters() const {
  TransportCounters c;
  c.write_timeouts = write_timeouts_.load();
  c.hull_readers = hull_writer_.Counters().matched_readers;
  return c;
}

}  // namespace silnet::node
