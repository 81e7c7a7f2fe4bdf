#include "aggregator/ingest/still_collector.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <thread>

#include "shared/dds/participant.h"
#include "shared/dds/still_command.h"
#include "shared/dds/topics.h"
#include "shared/util/check.h"
#include "shared/util/realtime_clock.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

const char* PartName(silnet_wire_StillPart part) {
  return part == silnet_wire_STILL_PHOTO ? "photo" : "silhouette";
}

// One camera's state during the collection.
struct CameraTrack {
  CollectedStill result;
  uint64_t from_frame = 0;
  std::optional<StillAssembly> assembly;
  bool seen = false;              // its node's CameraInfo arrived
  Clock::time_point seen_at{};    // when its newest CameraInfo arrived
  Clock::time_point asked_at{};   // when the capture was last asked for
  uint32_t asked_readers = 0;     // command readers matched then
  Clock::time_point last_news{};  // the newest chunk (or the first request)
  Clock::time_point last_ask{};   // the newest request of any kind
};

class Collector {
 public:
  explicit Collector(const StillCollectorOptions& options)
      : options_(options),
        participant_(options.domain),
        still_topic_(participant_),
        command_topic_(participant_),
        info_topic_(participant_),
        still_reader_(still_topic_, options.qos),
        info_reader_(info_topic_, options.qos),
        command_writer_(command_topic_, options.qos) {
    still_id_ = options.still_id != 0 ? options.still_id : static_cast<uint64_t>(RealtimeNowNs());
    for (const StillTarget& target : options.targets) {
      CameraTrack track;
      track.result.camera_id = target.camera_id;
      track.from_frame = target.from_frame;
      track.assembly.emplace(still_id_);
      index_[target.camera_id] = tracks_.size();
      tracks_.push_back(std::move(track));
    }
  }

  StillCollection Run(Progress* progress) {
    const auto start = Clock::now();
    Discover();
    for (CameraTrack& t : tracks_)
      AskForStill(t);
    const auto deadline = Clock::now() + options_.timeout;
    size_t reported = 0;
    while (Clock::now() < deadline && !(progress && progress->cancelled())) {
      still_reader_.WaitForData(std::chrono::milliseconds(50));
      TakeInfos();
      TakeChunks();
      const size_t done = Finished();
      if (progress && done > reported) progress->Advance(done - reported);
      reported = done;
      // Done when every camera whose node is there has its still; a node that appears late
      // is waited for.
      if (done + Absent() == tracks_.size()) break;
      AskAgain();
    }
    StillCollection collection;
    collection.still_id = still_id_;
    for (CameraTrack& t : tracks_) {
      if (!t.result.complete && t.result.reason.empty()) t.result.reason = Unanswered(t);
      if (!t.result.complete) spdlog::warn("still {}: {}", t.result.camera_id, t.result.reason);
      t.result.chunks = t.assembly->counts();
      collection.cameras.push_back(std::move(t.result));
    }
    collection.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return collection;
  }

 private:
  // Waits until every target's node is known (or the discovery time is up), so the commands,
  // which are not kept for late readers, reach them.
  void Discover() {
    const auto until = Clock::now() + options_.discovery;
    while (Clock::now() < until && Absent() > 0) {
      info_reader_.WaitForData(std::chrono::milliseconds(50));
      TakeInfos();
    }
    const size_t present = tracks_.size() - Absent();
    command_writer_.WaitForReaders(static_cast<uint32_t>(present), std::chrono::milliseconds(2000));
    spdlog::info("still {}: {} of {} camera nodes present", still_id_, present, tracks_.size());
  }

  // Marks the cameras whose node announced itself (CameraInfo) as present.
  void TakeInfos() {
    info_reader_.Take([&](const silnet_wire_CameraInfo& info, const dds_sample_info_t&) {
      const auto it = index_.find(dds::ReadBoundedString(info.camera_id));
      if (it == index_.end()) return;
      tracks_[it->second].seen = true;
      tracks_[it->second].seen_at = Clock::now();
    });
  }

  // Cameras with no sign of a node: no CameraInfo and no chunk.
  size_t Absent() const {
    return static_cast<size_t>(std::count_if(
        tracks_.begin(), tracks_.end(),
        [](const CameraTrack& t) { return !t.seen && t.assembly->counts().accepted == 0; }));
  }

  void Send(silnet_wire_Command command, const std::string& camera) {
    command.command_id = next_command_id_++;
    dds::CopyBoundedString("aggregator", command.issuer, "issuer");
    dds::CopyBoundedString(camera, command.target, "target");
    command.still_id = still_id_;
    command_writer_.Write(command);
  }

  void AskForStill(CameraTrack& t) {
    silnet_wire_Command command{};
    command.kind = silnet_wire_COMMAND_CAPTURE_STILL;
    command.from_frame = t.from_frame;
    if (options_.background) {
      dds::CopyBoundedString(dds::kStillKind, command.parameter.name, "parameter name");
      dds::CopyBoundedString(dds::kBackgroundStill, command.parameter.value, "parameter value");
    }
    Send(command, t.result.camera_id);
    ++t.result.requests;
    t.last_ask = t.asked_at = Clock::now();
    t.asked_readers = command_writer_.Counters().matched_readers;
    if (t.last_news == Clock::time_point{}) t.last_news = t.last_ask;
  }

  void TakeChunks() {
    still_reader_.Take(
        [&](const silnet_wire_Still& sample, const dds_sample_info_t&) {
          const auto it = index_.find(dds::ReadBoundedString(sample.camera_id));
          if (it == index_.end() || sample.still_id != still_id_) return;  // not ours
          CameraTrack& t = tracks_[it->second];
          if (t.result.complete) return;
          t.last_news = Clock::now();
          const ChunkVerdict verdict = t.assembly->Accept(sample);
          if (verdict == ChunkVerdict::kCorrupt || verdict == ChunkVerdict::kMalformed) {
            spdlog::info("still {}: {} chunk {} rejected ({})", t.result.camera_id,
                         PartName(sample.part), sample.chunk_index,
                         verdict == ChunkVerdict::kCorrupt ? "checksum" : "inconsistent");
          }
          if (t.assembly->Complete()) Finish(t);
        },
        100000);
  }

  void Finish(CameraTrack& t) {
    const std::string problem = t.assembly->Decode(&t.result.photo, &t.result.silhouette);
    if (!problem.empty()) {
      ++t.result.bad_images;
      spdlog::warn("still {}: {}; fetching it again", t.result.camera_id, problem);
      return;
    }
    const StillPartAssembly& photo = t.assembly->part(silnet_wire_STILL_PHOTO);
    t.result.complete = true;
    t.result.frame_index = photo.frame_index;
    t.result.frame_flags = t.assembly->part(silnet_wire_STILL_SILHOUETTE).frame_flags;
    t.result.capture_time_ns = photo.capture_time_ns;
    t.result.photo_encoding = photo.encoding;
    spdlog::info("still {}: frame {}, {}x{} complete", t.result.camera_id, photo.frame_index,
                 photo.width, photo.height);
  }

  size_t Finished() const {
    return static_cast<size_t>(std::count_if(
        tracks_.begin(), tracks_.end(), [](const CameraTrack& t) { return t.result.complete; }));
  }

  // Cameras silent for a while: missing chunks are asked for again (a part of which nothing
  // arrived, whole). A camera that has sent nothing is asked for its still again only when
  // its node announced itself after the last request (it appeared late or restarted) or more
  // command readers have matched since (the request may have missed it): a node that has the
  // request may be waiting for the frame asked for, and the reliable command needs no
  // repeating.
  void AskAgain() {
    const auto now = Clock::now();
    for (CameraTrack& t : tracks_) {
      if (t.result.complete || now - t.last_news < options_.ask_again_after ||
          now - t.last_ask < options_.ask_again_after) {
        continue;
      }
      const bool any = t.assembly->part(silnet_wire_STILL_PHOTO).started() ||
                       t.assembly->part(silnet_wire_STILL_SILHOUETTE).started();
      if (!any) {
        const bool missed = (t.seen && t.seen_at > t.asked_at) ||
                            command_writer_.Counters().matched_readers > t.asked_readers;
        if (missed) AskForStill(t);
        continue;
      }
      for (silnet_wire_StillPart part : {silnet_wire_STILL_PHOTO, silnet_wire_STILL_SILHOUETTE}) {
        const StillPartAssembly& assembly = t.assembly->part(part);
        const std::vector<std::pair<uint32_t, uint32_t>> missing =
            assembly.started() ? assembly.Missing()
                               : std::vector<std::pair<uint32_t, uint32_t>>{{0, UINT32_MAX}};
        for (const auto& [first, last] : missing) {
          silnet_wire_Command command{};
          command.kind = silnet_wire_COMMAND_RESEND_STILL;
          command.still_part = part;
          command.from_frame = first;
          command.to_frame = last;
          Send(command, t.result.camera_id);
          ++t.result.resend_requests;
          spdlog::info("still {}: asking again for {} chunks {}..{}", t.result.camera_id,
                       PartName(part), first, last);
        }
      }
      t.last_ask = now;
    }
  }

  std::string Unanswered(const CameraTrack& t) const {
    if (!t.seen) return "no node of this camera was found";
    const ChunkCounts& c = t.assembly->counts();
    if (c.accepted == 0) return "its node did not answer";
    return "its still did not arrive completely in time";
  }

  const StillCollectorOptions& options_;
  uint64_t still_id_ = 0;
  uint64_t next_command_id_ = 1;
  dds::Participant participant_;
  dds::Topic<silnet_wire_Still> still_topic_;
  dds::Topic<silnet_wire_Command> command_topic_;
  dds::Topic<silnet_wire_CameraInfo> info_topic_;
  dds::Reader<silnet_wire_Still> still_reader_;
  dds::Reader<silnet_wire_CameraInfo> info_reader_;
  dds::Writer<silnet_wire_Command> command_writer_;
  std::vector<CameraTrack> tracks_;
  std::map<std::string, size_t> index_;
};

}  // namespace

size_t StillCollection::complete() const {
  return static_cast<size_t>(std::count_if(cameras.begin(), cameras.end(),
                                           [](const CollectedStill& c) { return c.complete; }));
}

StillCollection CollectStills(const StillCollectorOptions& options, Progress* progress) {
  if (options.targets.empty()) throw InputError("no cameras to ask for stills");
  for (const StillTarget& target : options.targets) {
    if (target.camera_id.empty() || target.camera_id.size() > 31)
      throw InputError("camera id '" + target.camera_id + "' is not a valid camera id");
  }
  Collector collector(options);
  return collector.Run(progress);
}

}  // namespace silnet::aggregator
