#pragma once
// QoS policies named for their use in silnet (DESIGN.md "QoS"; DDS_NOTES.md for why).

#include <dds/dds.h>

#include <chrono>
#include <cstdint>

namespace silnet::dds {

// The kinds of stream silnet has; each maps to one set of policies.
enum class QosProfile {
  // Per-frame streams (HullFrame, Contour) that must lose nothing: reliable, keep-all with
  // resource limits, transient-local so a late reader receives the writer's recent history.
  kFrameStream,
  // Latched state (CameraInfo, Calibration): reliable, transient-local, last sample per key.
  kLatched,
  // Commands: reliable, volatile, keep-all, expiring after a lifespan.
  kCommand,
  // Periodic health (NodeStatus): reliable, last sample per key.
  kStatus,
  // Large payloads (Still chunks): reliable, keep-all.
  kBulk,
};

// Tunables of the profiles; the defaults suit a 30 fps camera network.
struct QosSettings {
  // Samples per instance a frame-stream writer keeps for late readers (about 2 min at 30 fps).
  int32_t frame_history = 4096;
  // Samples per instance a reader may hold before the writer is throttled.
  int32_t reader_limit = 16384;
  // Longest a reliable write may block under back-pressure before returning a timeout.
  std::chrono::milliseconds max_blocking_time{1000};
  // How long a command stays valid.
  std::chrono::milliseconds command_lifespan{10000};
};

// Owns a dds_qos_t.
class Qos {
 public:
  Qos();
  ~Qos();
  Qos(Qos&& other) noexcept;
  Qos& operator=(Qos&& other) noexcept;
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;

  // Policies for a writer of the given profile.
  static Qos ForWriter(QosProfile profile, const QosSettings& settings = {});
  // Policies for a reader of the given profile (compatible with ForWriter).
  static Qos ForReader(QosProfile profile, const QosSettings& settings = {});

  const dds_qos_t* get() const { return qos_; }
  dds_qos_t* get() { return qos_; }

 private:
  dds_qos_t* qos_;
};

// Converts a std::chrono duration to Cyclone's nanoseconds.
inline dds_duration_t ToDdsDuration(std::chrono::nanoseconds d) {
  return d.count();
}

}  // namespace silnet::dds
