#pragma once
// The wall clock silnet stamps frames with: CLOCK_REALTIME, shared by the processes of one
// host (and across hosts as far as their clocks are synchronised).

#include <cstdint>

namespace silnet {

// Current CLOCK_REALTIME in nanoseconds since the Unix epoch.
int64_t RealtimeNowNs();

}  // namespace silnet
