#pragma once
// The node's DDS side: writers for its streams (HullFrame, Contour, CameraInfo, NodeStatus,
// Still) and the reader of commands addressed to it.

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "node/publish/still_store.h"
#include "shared/dds/sample_conversions.h"
#include "shared/dds/topics.h"

namespace silnet::node {

// Transport totals.
struct TransportCounters {
  uint64_t write_timeouts = 0;  // writes that waited for slow readers and were retried
  uint32_t hull_readers = 0;    // readers matched on the HullFrame topic
};

// Faults a test injects into the first sending of a still's chunks (-1: none), so the
// aggregator's re-requests and checksums are exercised between real processes.
struct StillChunkFaults {
  int drop_chunk = -1;     // this chunk of each part is not sent
  int corrupt_chunk = -1;  // this chunk of each part is sent with one byte flipped
};

// Writers and the command reader of one camera node.
class NodeTransport {
 public:
  // Joins the domain and creates the topics. Throws DdsError if DDS fails.
  NodeTransport(const dds::DomainConfig& domain, std::string camera_id,
                const dds::QosSettings& qos = {});

  // Writes a frame sample, retrying while reliable readers push back, until it is written
  // (true) or `stop` becomes true (false).
  bool PublishHull(const FrameRecord& record, const std::atomic<bool>& stop);
  bool PublishContour(const FrameRecord& record, const std::atomic<bool>& stop);
  void PublishCameraInfo(const CameraInfoRecord& info);
  void PublishStatus(const silnet_wire_NodeStatus& status);
  // Sends chunks [first, last] (clamped to the image's) of one part of `still`, each of at
  // most `chunk_bytes` with its CRC-32 and the whole image's; `faults` drop or corrupt one.
  // Returns the chunks written; stops early (false writes) only when `stop` becomes true.
  size_t PublishStillChunks(const EncodedStill& still, silnet_wire_StillPart part, uint32_t first,
                            uint32_t last, size_t chunk_bytes, const StillChunkFaults& faults,
                            const std::atomic<bool>& stop);

  // Commands addressed to this camera (or to "*") that arrived, waiting up to `wait`.
  std::vector<silnet_wire_Command> TakeCommands(std::chrono::milliseconds wait);
  // Waits until readers acknowledged every frame sample, up to `timeout`.
  bool WaitForAcknowledgements(std::chrono::milliseconds timeout);
  TransportCounters Counters() const;

 private:
  template <class Sample>
  bool WriteRetrying(dds::Writer<Sample>& writer, const Sample& sample,
                     const std::atomic<bool>& stop);

  std::string camera_id_;
  dds::Participant participant_;
  dds::Topic<silnet_wire_HullFrame> hull_topic_;
  dds::Topic<silnet_wire_Contour> contour_topic_;
  dds::Topic<silnet_wire_CameraInfo> info_topic_;
  dds::Topic<silnet_wire_NodeStatus> status_topic_;
  dds::Topic<silnet_wire_Still> still_topic_;
  dds::Topic<silnet_wire_Command> command_topic_;
  dds::Writer<silnet_wire_HullFrame> hull_writer_;
  dds::Writer<silnet_wire_Contour> contour_writer_;
  dds::Writer<silnet_wire_CameraInfo> info_writer_;
  dds::Writer<silnet_wire_NodeStatus> status_writer_;
  dds::Writer<silnet_wire_Still> still_writer_;
  dds::Reader<silnet_wire_Command> command_reader_;
  std::atomic<uint64_t> write_timeouts_{0};
};

}  // namespace silnet::node
