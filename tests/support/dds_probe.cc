// silnet-dds-probe: a minimal second process for DDS tests.
//   silnet-dds-probe publish N [S]  wait up to S seconds (default 20) for a reader (exit 3
//                                   if none), write N HullFrame samples (camera probe,
//                                   frame_index 0..N-1), wait for acknowledgements
//   silnet-dds-probe receive N S    print each sample's frame_index; exit 0 once N
//                                   arrived, 3 after S seconds without them
//   silnet-dds-probe try-write T    create a writer for topic T (calibration or command):
//                                   exit 0 if allowed, 6 if DDS Security refuses it
// The domain comes from SILNET_DDS_* (shared/dds/domain_config.h).

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "shared/dds/topics.h"

using namespace silnet::dds;

namespace {

// 0 when a writer for T can be created, 6 when DDS Security refuses it.
template <class T>
int TryWrite(const Participant& participant) {
  try {
    Topic<T> topic(participant);
    Writer<T> writer(topic);
    return 0;
  } catch (const DdsError& e) {
    std::fprintf(stderr, "silnet-dds-probe: %s\n", e.what());
    return e.code() == DDS_RETCODE_NOT_ALLOWED_BY_SECURITY ? 6 : 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(
        stderr,
        "usage: silnet-dds-probe publish N [SECONDS] | receive N SECONDS | try-write TOPIC\n");
    return 2;
  }
  const std::string mode = argv[1];
  const int count = std::atoi(argv[2]);
  try {
    Participant participant;
    if (mode == "try-write") {
      const std::string topic = argv[2];
      if (topic == "calibration") return TryWrite<silnet_wire_Calibration>(participant);
      if (topic == "command") return TryWrite<silnet_wire_Command>(participant);
      std::fprintf(stderr, "unknown topic '%s'\n", topic.c_str());
      return 2;
    }
    Topic<silnet_wire_HullFrame> topic(participant);
    if (mode == "publish") {
      Writer<silnet_wire_HullFrame> writer(topic);
      const int wait_seconds = argc >= 4 ? std::atoi(argv[3]) : 20;
      if (!writer.WaitForReaders(1, std::chrono::seconds(wait_seconds))) {
        std::fprintf(stderr, "no reader matched\n");
        return 3;
      }
      for (int i = 0; i < count; ++i) {
        silnet_wire_HullFrame sample{};
        CopyBoundedString("probe", sample.camera_id, "camera id");
        sample.frame_index = static_cast<uint64_t>(i);
        if (!writer.Write(sample)) return 4;
      }
      return writer.WaitForAcknowledgements(std::chrono::seconds(20)) ? 0 : 5;
    }
    if (mode == "receive" && argc >= 4) {
      Reader<silnet_wire_HullFrame> reader(topic);
      const auto deadline =
          std::chrono::steady_clock::now() + std::chrono::seconds(std::atoi(argv[3]));
      int received = 0;
      while (received < count && std::chrono::steady_clock::now() < deadline) {
        reader.WaitForData(std::chrono::milliseconds(100));
        received += static_cast<int>(
            reader.Take([](const silnet_wire_HullFrame& s, const dds_sample_info_t&) {
              std::printf("%llu\n", static_cast<unsigned long long>(s.frame_index));
            }));
      }
      std::fflush(stdout);
      return received >= count ? 0 : 3;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "silnet-dds-probe: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "unknown mode '%s'\n", mode.c_str());
  return 2;
}
