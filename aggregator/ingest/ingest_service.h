#pragma once
// The aggregator's ingest: it subscribes to every node's streams, validates each sample
// (malformed ones are counted and dropped), stores accepted frames durably in the session
// store (duplicates counted, stored once), tracks per camera and session which frames have
// arrived, and asks nodes to re-send what is missing (COMMAND_RESEND) — gaps inside the
// stream, and frames a node reports published that never arrived. A camera whose stream
// stops is reported stalled (and again when it resumes); a store that cannot write (a full
// disk) is reported, and the frames it lost are asked for again once it writes again.

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "aggregator/ingest/session_store.h"
#include "shared/dds/domain_config.h"
#include "shared/dds/qos.h"

namespace silnet::aggregator {

// Settings of the ingest.
struct IngestOptions {
  std::filesystem::path store_dir;  // session logs go here
  dds::DomainConfig domain;
  dds::QosSettings qos;
  std::chrono::milliseconds resend_grace{400};      // a gap must be this old before asking
  std::chrono::milliseconds resend_interval{1500};  // and asking again waits this long
  uint64_t max_resend_frames = 2000;                // frames asked for in one command
  std::chrono::milliseconds stall_after{3000};      // a camera silent this long has stalled
  // Called (from Poll) with every hull frame of a camera's newest session once it is stored,
  // for consumers that follow the streams in memory; may be empty.
  std::function<void(const FrameRecord&)> on_hull_stored;
  // The same for every Contour record once it is stored (of any session); may be empty.
  std::function<void(const FrameRecord&)> on_contour_stored;
};

// Counters of one camera.
struct CameraIngestStatus {
  std::string camera_id;
  uint32_t session = 0;      // newest session seen
  uint64_t frames_held = 0;  // hull frames of that session in the store
  uint64_t first_frame = 0, last_frame = 0;
  uint64_t missing = 0;   // frames not (yet) held: below the newest, or published beyond it
  uint64_t received = 0;  // HullFrame samples received (all sessions)
  uint64_t contours = 0;  // Contour samples stored
  uint64_t duplicates = 0;
  uint64_t out_of_order = 0;  // arrived after a later frame of the same session
  uint64_t malformed = 0;
  uint64_t resend_requests = 0;
  uint64_t resent_received = 0;    // samples flagged FRAME_RESENT that filled a gap
  uint64_t store_failures = 0;     // samples the store could not write (disk full, ...)
  bool stalled = false;            // no sample for IngestOptions::stall_after
  uint64_t stalls = 0;             // times the stream stalled
  double seconds_since_last = -1;  // since the last sample (negative: none yet)
  std::string node_state;          // from the node's last NodeStatus
  double node_fps = 0.0;
  double node_cpu_percent = 0.0;  // of one core, mean over the node's statuses while running
  uint64_t node_published = 0;
  uint64_t node_dropped = 0;         // frames the node reports lost before publishing
  uint64_t node_flagged = 0;         // frames the node published flagged as a problem
  double seconds_since_status = -1;  // since the node's last NodeStatus (negative: none)
  bool node_alive = false;           // a NodeStatus arrived in the last 3 s
  // Capture to arrival of HullFrame samples first sent (not re-sent), milliseconds; on one
  // host (or with synchronised clocks) this is the end-to-end latency. 0 without samples.
  double latency_median_ms = 0.0, latency_p99_ms = 0.0;
};

// Totals over all cameras.
struct IngestTotals {
  uint64_t received = 0, stored = 0, duplicates = 0, malformed = 0, out_of_order = 0,
           resend_requests = 0, missing = 0, store_failures = 0, stalls = 0;
  int cameras_stalled = 0;        // cameras stalled now
  uint64_t contours_overdue = 0;  // hull frames whose contour has not arrived (yet)
  uint64_t dds_samples_lost = 0;  // reported by DDS on the frame readers
  uint64_t dds_samples_rejected = 0;
  uint64_t node_dropped = 0, node_flagged = 0;  // as the nodes' last statuses say
};

// Subscribes, validates, stores, tracks and requests re-sends. One thread calls Poll().
class IngestService {
 public:
  explicit IngestService(IngestOptions options);
  ~IngestService();

  // Opens the store (re-indexing what it holds) and joins DDS. Throws InputError/DdsError.
  void Open();
  // Takes everything that arrived (waiting up to `wait` for the first sample), stores it and
  // sends due re-send requests. Returns the number of samples handled.
  size_t Poll(std::chrono::milliseconds wait);
  std::vector<CameraIngestStatus> Status() const;
  IngestTotals Totals() const;
  // Flushes the store to the device.
  void Flush();
  // Writes a YAML summary of Status() to `path`.
  void WriteSummary(const std::filesystem::path& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace silnet::aggregator
