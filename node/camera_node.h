#pragma once
// A camera node: capture -> segmentation -> hull + tangent table (+ contour) -> DDS, on
// separate threads so capture never waits for processing or the network:
//   capture thread     reads the source; frames that find the processing queue full are
//                      dropped (and published flagged, so every frame index is accounted for)
//   processing thread  FrameProcessor; frames lost before it (index gaps) become flagged
//                      FRAME_DROPPED frames; keeps the local history and the recording
//   publishing thread  writes HullFrame and Contour samples, retrying under back-pressure
//   control thread     NodeStatus every status period, commands (start, stop, record,
//                      set parameter, capture still, resend)
//   still thread       encodes a commanded still (the first frame at or after the frame
//                      asked for, with its silhouette) and sends it in checksummed chunks;
//                      sends chunks again when the aggregator asks

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "node/capture/capture_source.h"
#include "node/pipeline/frame_processor.h"
#include "node/publish/node_transport.h"
#include "shared/dds/domain_config.h"
#include "shared/dds/qos.h"

namespace silnet::node {

// Settings of a camera node.
struct CameraNodeOptions {
  FrameProcessorOptions processing;  // processing.camera_id names the camera
  size_t processing_queue = 32;      // frames waiting for segmentation
  size_t publish_queue = 16384;      // encoded frames waiting for the network
  size_t history_frames = 9000;      // frames kept for resend (5 minutes at 30 fps)
  std::filesystem::path record_dir;  // session log folder; empty = not recording
  std::chrono::milliseconds status_period{1000};
  std::chrono::milliseconds linger{5000};  // stay after a finite source ends (for resends)
  bool start_stopped = false;              // wait for COMMAND_START before publishing
  // Capture waits for segmentation instead of dropping frames when it falls behind: for
  // replayed files and tests on a busy machine, never for a live camera (which cannot wait).
  bool lossless = false;
  size_t still_chunk_bytes = 256 * 1024;  // Still samples carry at most this much image
  StillChunkFaults still_faults;          // tests only: chunks dropped or corrupted once
  dds::DomainConfig domain;
  dds::QosSettings qos;

  // A readable reason if the options are unusable, empty otherwise.
  std::string Validate() const;
};

// Totals of a node's run.
struct NodeCounters {
  uint64_t captured = 0;   // frames the source delivered (including unusable ones)
  uint64_t processed = 0;  // frames segmented and encoded
  uint64_t published = 0;  // HullFrame samples written (live)
  uint64_t dropped = 0;    // frame indices published as FRAME_DROPPED
  uint64_t flagged = 0;    // frames published with any problem flag
  uint64_t resent = 0;     // frames re-sent on request
  uint64_t commands = 0;   // commands obeyed
  uint64_t stills = 0;     // stills captured and sent
  uint64_t still_chunks_resent = 0;
  uint64_t capture_errors = 0;
};

// Runs one camera node until stopped or its finite source is done.
class CameraNode {
 public:
  CameraNode(CameraNodeOptions options, std::unique_ptr<CaptureSource> source);
  ~CameraNode();
  CameraNode(const CameraNode&) = delete;
  CameraNode& operator=(const CameraNode&) = delete;

  // Opens the source and DDS, runs until `stop` becomes true or a finite source has ended,
  // everything was published and `linger` passed; then flushes the recording. Throws
  // CaptureError / InputError / DdsError if it cannot start.
  void Run(const std::atomic<bool>& stop);
  NodeCounters Counters() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// The node's software version, for CameraInfo.
const char* NodeVersion();

}  // namespace silnet::node
