// silnet-dds-probe: a minimal second process for DDS tests.
//   silnet-dds-probe publish N [S]  wait up to S seconds (default 20) for a reader (exit 3
//                                   if none), write N HullFrame samples (camera probe,
//                                   frame_index 0..N-1), wait for acknowledgements
//   silnet-dds-probe receive N S    print each sample's frame_index; exit 0 once N
//                                   arrived, 3 after S seconds without them
//   silnet-dds-probe try-write T    create a writer for topic T (calibration or command):
//                                   exit 0 if allowed, 6 if DDS Security refuses it
//   silnet-dds-probe misbehave C    as camera C, once a reader matched: valid frames 0..9,
//                                   frames 3 and 4 again, 11 before 10, 12; then three
//                                   malformed frames (13: bad CRC, 14: zero image size,
//                                   15: truncated payload) and one without a camera id
// The domain comes from SILNET_DDS_* (shared/dds/domain_config.h).

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "shared/dds/topics.h"
#include "shared/silhouette/hull_codec.h"

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

// A 640x480 HullFrame of `camera` with a valid 40x40 square hull.
silnet_wire_HullFrame SquareFrame(const std::string& camera, uint64_t index,
                                  std::vector<uint8_t>* payload) {
  const std::vector<Eigen::Vector2d> square{{10.5, 10.5}, {50.5, 10.5}, {50.5, 50.5}, {10.5, 50.5}};
  *payload =
      silnet::EncodeHull({silnet::SilhouetteHull(square, std::vector<bool>(4, false)), 1600});
  silnet_wire_HullFrame sample{};
  CopyBoundedString(camera, sample.camera_id, "camera id");
  sample.session = 1;
  sample.frame_index = index;
  sample.capture_time_ns = static_cast<int64_t>(index) * 33'333'333;
  sample.image_width = 640;
  sample.image_height = 480;
  sample.hull._buffer = payload->data();
  sample.hull._length = static_cast<uint32_t>(payload->size());
  sample.hull._maximum = sample.hull._length;
  return sample;
}

int Misbehave(const Participant& participant, const std::string& camera) {
  Topic<silnet_wire_HullFrame> topic(participant);
  Writer<silnet_wire_HullFrame> writer(topic);
  if (!writer.WaitForReaders(1, std::chrono::seconds(20))) return 3;
  std::vector<uint8_t> payload;
  auto send = [&](const silnet_wire_HullFrame& sample) { return writer.Write(sample); };
  bool ok = true;
  for (uint64_t index : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 3, 4, 11, 10, 12})
    ok = ok && send(SquareFrame(camera, index, &payload));
  silnet_wire_HullFrame bad_crc = SquareFrame(camera, 13, &payload);
  payload.back() ^= 0x5a;
  ok = ok && send(bad_crc);
  silnet_wire_HullFrame no_size = SquareFrame(camera, 14, &payload);
  no_size.image_width = 0;
  ok = ok && send(no_size);
  silnet_wire_HullFrame truncated = SquareFrame(camera, 15, &payload);
  truncated.hull._length = 3;
  ok = ok && send(truncated);
  silnet_wire_HullFrame anonymous = SquareFrame(camera, 16, &payload);
  anonymous.camera_id[0] = '\0';
  ok = ok && send(anonymous);
  if (!ok) return 4;
  return writer.WaitForAcknowledgements(std::chrono::seconds(20)) ? 0 : 5;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(
        stderr,
        "usage: silnet-dds-probe publish N [SECONDS] | receive N SECONDS | try-write TOPIC | "
        "misbehave CAMERA\n");
    return 2;
  }
  const std::string mode = argv[1];
  const int count = std::atoi(argv[2]);
  try {
    Participant participant;
    if (mode == "misbehave") return Misbehave(participant, argv[2]);
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
