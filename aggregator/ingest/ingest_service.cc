#include "aggregator/ingest/ingest_service.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <opencv2/core/persistence.hpp>
#include <random>

#include "shared/dds/sample_conversions.h"
#include "shared/io/replace_yaml.h"
#include "shared/silhouette/frame_sample_check.h"
#include "shared/util/check.h"
#include "shared/util/realtime_clock.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

struct IngestService::Impl {
  struct Track {
    CameraIngestStatus status;
    FrameIndexSet held;     // hull frames of the newest session
    int contour_every = 0;  // from the node's CameraInfo (0: no contours expected)
    std::map<uint64_t, Clock::time_point> contour_due;  // frames whose contour has not arrived
    std::map<uint64_t, Clock::time_point> asked;        // gap start -> when last requested
    Clock::time_point first_gap_seen{};
    Clock::time_point last_sample{};
    bool any = false;
    std::vector<float> latencies_ms;  // reservoir of capture-to-arrival latencies
    uint64_t latency_samples = 0;
    uint64_t cpu_statuses = 0;  // NodeStatus samples averaged into node_cpu_percent
    Clock::time_point last_status{};
  };

  IngestOptions options;
  SessionStore store;
  std::unique_ptr<dds::Participant> participant;
  std::unique_ptr<dds::Topic<silnet_wire_HullFrame>> hull_topic;
  std::unique_ptr<dds::Topic<silnet_wire_Contour>> contour_topic;
  std::unique_ptr<dds::Topic<silnet_wire_CameraInfo>> info_topic;
  std::unique_ptr<dds::Topic<silnet_wire_NodeStatus>> status_topic;
  std::unique_ptr<dds::Topic<silnet_wire_Command>> command_topic;
  std::unique_ptr<dds::Reader<silnet_wire_HullFrame>> hull_reader;
  std::unique_ptr<dds::Reader<silnet_wire_Contour>> contour_reader;
  std::unique_ptr<dds::Reader<silnet_wire_CameraInfo>> info_reader;
  std::unique_ptr<dds::Reader<silnet_wire_NodeStatus>> status_reader;
  std::unique_ptr<dds::Writer<silnet_wire_Command>> command_writer;
  std::map<std::string, Track> tracks;
  uint64_t malformed_unknown = 0;
  uint64_t next_command_id = 1;
  bool store_failing = false;  // the last write failed; reported once until one succeeds
  std::mt19937_64 latency_random{1};

  explicit Impl(IngestOptions o) : options(std::move(o)), store(options.store_dir) {}

  Track& TrackFor(const std::string& camera_id) {
    Track& t = tracks[camera_id];
    t.status.camera_id = camera_id;
    return t;
  }

  void StartSession(Track& t, uint32_t session) {
    t.status.session = session;
    t.held = store.HullFrames(t.status.camera_id, session);
    t.asked.clear();
    t.contour_due.clear();
    t.any = !t.held.empty();
  }

  void OnHull(const FrameRecord& record) {
    if (const std::string reason = FindFrameSampleProblem(record, FramePayloadKind::kHull);
        !reason.empty()) {
      spdlog::warn("malformed HullFrame from '{}' (frame {}): {}", record.camera_id,
                   record.frame_index, reason);
      if (record.camera_id.empty()) {
        ++malformed_unknown;
      } else {
        ++TrackFor(record.camera_id).status.malformed;
      }
      return;
    }
    Track& t = TrackFor(record.camera_id);
    ++t.status.received;
    NoteSample(t);
    if (!(record.flags & silnet_wire_FRAME_RESENT) && record.capture_time_ns > 0)
      NoteLatency(t, (RealtimeNowNs() - record.capture_time_ns) * 1e-6);
    if (record.session > t.status.session) {
      if (t.any) RequestRestOfSession(t);
      StartSession(t, record.session);
    }
    const bool late = record.session == t.status.session && t.any &&
                      record.frame_index < t.held.max() &&
                      !(record.flags & silnet_wire_FRAME_RESENT);
    switch (store.Add(SessionRecordType::kHullFrame, record)) {
      case StoreResult::kDuplicate:
        ++t.status.duplicates;
        return;
      case StoreResult::kFailed:
        ++t.status.store_failures;
        ReportStoreFailure();
        return;
      case StoreResult::kStored:
        ReportStoreRecovered();
        break;
    }
    if (record.session != t.status.session) return;  // an older session's frame: stored
    if (late) ++t.status.out_of_order;
    if (record.flags & silnet_wire_FRAME_RESENT) ++t.status.resent_received;
    t.held.Insert(record.frame_index);
    if (options.on_hull_stored) options.on_hull_stored(record);
    t.any = true;
    const bool has_contour = t.contour_every > 0 &&
                             record.frame_index % static_cast<uint64_t>(t.contour_every) == 0 &&
                             !HullHasNoContour(record);
    if (has_contour && !store.HasContour(record.camera_id, record.session, record.frame_index)) {
      t.contour_due.emplace(record.frame_index, Clock::now());
    }
  }

  void ReportStoreFailure() {
    if (store_failing) return;
    store_failing = true;
    spdlog::error(
        "session store cannot write: {}; frames are dropped and will be asked for again once it "
        "writes",
        store.last_error());
  }

  void ReportStoreRecovered() {
    if (!store_failing) return;
    store_failing = false;
    spdlog::warn("session store writes again; asking the nodes for the frames it lost");
  }

  // A camera that sent frames and then none for stall_after, without its node saying that
  // its source ended, that it was stopped or that it exited, is stalled until a frame
  // arrives.
  void DetectStalls() {
    const auto now = Clock::now();
    for (auto& [id, t] : tracks) {
      if (t.last_sample == Clock::time_point{} || t.status.stalled) continue;
      const std::string& state = t.status.node_state;
      if (state.starts_with("ended") || state.starts_with("stopped") || state.starts_with("exited"))
        continue;
      if (now - t.last_sample < options.stall_after) continue;
      t.status.stalled = true;
      ++t.status.stalls;
      spdlog::warn("{} stalled: no frame for {:.1f} s (newest frame {} of session {})", id,
                   std::chrono::duration<double>(now - t.last_sample).count(),
                   t.any ? t.held.max() : 0, t.status.session);
    }
  }

  // Keeps a uniform sample of at most 4096 latencies (reservoir sampling, fixed seed).
  void NoteLatency(Track& t, double ms) {
    constexpr size_t kKeep = 4096;
    ++t.latency_samples;
    if (t.latencies_ms.size() < kKeep) {
      t.latencies_ms.push_back(static_cast<float>(ms));
      return;
    }
    const uint64_t slot = latency_random() % t.latency_samples;
    if (slot < kKeep) t.latencies_ms[slot] = static_cast<float>(ms);
  }

  void NoteSample(Track& t) {
    t.last_sample = Clock::now();
    if (!t.status.stalled) return;
    t.status.stalled = false;
    spdlog::warn("{} resumed after a stall", t.status.camera_id);
  }

  // Once the node's contour rate is known (its CameraInfo may arrive after the first
  // frames), every frame held that should have a contour and has none is waited for; frames
  // the node flagged dropped or unusable have none to wait for.
  void ScheduleMissingContours(Track& t) {
    if (t.contour_every <= 0 || !t.any) return;
    const auto every = static_cast<uint64_t>(t.contour_every);
    const auto now = Clock::now();
    const FrameIndexSet without_contour =
        store.HullFramesWithoutContour(t.status.camera_id, t.status.session);
    for (const FrameRange& range : t.held.ranges()) {
      for (uint64_t f = (range.first + every - 1) / every * every; f <= range.last; f += every) {
        if (!without_contour.Contains(f) &&
            !store.HasContour(t.status.camera_id, t.status.session, f))
          t.contour_due.emplace(f, now);
      }
    }
  }

  void OnContour(const FrameRecord& record) {
    if (const std::string reason = FindFrameSampleProblem(record, FramePayloadKind::kContour);
        !reason.empty()) {
      spdlog::warn("malformed Contour from '{}' (frame {}): {}", record.camera_id,
                   record.frame_index, reason);
      ++TrackFor(record.camera_id.empty() ? "?" : record.camera_id).status.malformed;
      return;
    }
    Track& t = TrackFor(record.camera_id);
    switch (store.Add(SessionRecordType::kContour, record)) {
      case StoreResult::kStored:
        ++t.status.contours;
        ReportStoreRecovered();
        if (options.on_contour_stored) options.on_contour_stored(record);
        break;
      case StoreResult::kFailed:
        ++t.status.store_failures;
        ReportStoreFailure();
        return;  // still due: asked for again
      case StoreResult::kDuplicate:
        break;
    }
    if (record.session == t.status.session) t.contour_due.erase(record.frame_index);
  }

  void RequestResend(Track& t, uint64_t first, uint64_t last) {
    silnet_wire_Command command{};
    command.command_id = next_command_id++;
    dds::CopyBoundedString("aggregator", command.issuer, "issuer");
    dds::CopyBoundedString(t.status.camera_id, command.target, "target");
    command.kind = silnet_wire_COMMAND_RESEND;
    command.session = t.status.session;
    command.from_frame = first;
    command.to_frame = last;
    command_writer->Write(command);
    ++t.status.resend_requests;
    spdlog::info("asking {} to re-send frames {}..{} of session {}", t.status.camera_id, first,
                 last == std::numeric_limits<uint64_t>::max() ? "end" : std::to_string(last),
                 t.status.session);
  }

  // A camera's status now; the latency quantiles (a selection over the reservoir) only if
  // `with_latency`, as totals polled every loop do not need them.
  CameraIngestStatus Snapshot(const Track& t, bool with_latency) const {
    const auto now = Clock::now();
    CameraIngestStatus status = t.status;
    status.frames_held = t.held.size();
    if (t.any) {
      status.first_frame = t.held.min();
      status.last_frame = t.held.max();
      for (const FrameRange& gap : t.held.Missing(0))
        status.missing += gap.last - gap.first + 1;
      // Frames the node reports published beyond the newest one held.
      if (t.status.node_published > t.held.max() + 1)
        status.missing += t.status.node_published - t.held.max() - 1;
    }
    if (with_latency && !t.latencies_ms.empty()) {
      std::vector<float> values = t.latencies_ms;
      const auto at = [&](size_t rank) {
        std::nth_element(values.begin(), values.begin() + static_cast<long>(rank), values.end());
        return values[rank];
      };
      status.latency_median_ms = at(values.size() / 2);
      status.latency_p99_ms = at(std::min(values.size() - 1, values.size() * 99 / 100));
    }
    if (t.last_status != Clock::time_point{}) {
      status.seconds_since_status = std::chrono::duration<double>(now - t.last_status).count();
      status.node_alive = status.seconds_since_status <= 3.0;
    }
    status.seconds_since_last = t.last_sample == Clock::time_point{}
                                    ? -1.0
                                    : std::chrono::duration<double>(now - t.last_sample).count();
    return status;
  }

  // A node started a new session (it restarted, perhaps after a crash): once, ask it for
  // what the previous session's stream did not deliver — its gaps, contours that did not
  // arrive, and everything after the newest frame held. A node that records serves them
  // from its recording.
  void RequestRestOfSession(Track& t) {
    std::vector<FrameRange> wanted = t.held.Missing(0);
    // Frames held without their contour (the hull arrived, the contour did not): while the
    // node's contour rate is unknown, every frame of a session that has contours is due.
    const std::string& id = t.status.camera_id;
    const uint32_t session = t.status.session;
    uint64_t every = static_cast<uint64_t>(std::max(t.contour_every, 0));
    if (every == 0 && store.HasAnyContour(id, session)) every = 1;
    for (const FrameRange& range : every > 0 ? t.held.ranges() : std::vector<FrameRange>{}) {
      for (uint64_t f = (range.first + every - 1) / every * every; f <= range.last; f += every) {
        if (store.HasContour(id, session, f)) continue;
        if (!wanted.empty() && wanted.back().last + 1 == f && every == 1) {
          wanted.back().last = f;
        } else {
          wanted.push_back({f, f});
        }
      }
    }
    for (const FrameRange& range : wanted)
      RequestResend(t, range.first, range.last);
    RequestResend(t, t.held.max() + 1, std::numeric_limits<uint64_t>::max());
  }

  void RequestMissing() {
    const auto now = Clock::now();
    for (auto& [id, t] : tracks) {
      if (!t.any) continue;
      // Sessions number their frames from 0; anything below the newest frame held is a gap.
      std::vector<FrameRange> gaps = t.held.Missing(0);
      // Frames the node reports published beyond the newest one held, once the stream is quiet.
      if (t.status.node_published > t.held.max() + 1 &&
          now - t.last_sample > options.resend_grace) {
        gaps.push_back({t.held.max() + 1, t.status.node_published - 1});
      }
      // Frames whose contour is overdue are asked for again (their hull arrives twice).
      for (auto it = t.contour_due.begin(); it != t.contour_due.end();) {
        if (now - it->second < options.resend_grace) {
          ++it;
          continue;
        }
        FrameRange range{it->first, it->first};
        for (++it; it != t.contour_due.end() && it->first == range.last + 1 &&
                   now - it->second >= options.resend_grace;
             ++it) {
          range.last = it->first;
        }
        gaps.push_back(range);
      }
      if (gaps.empty()) {
        t.first_gap_seen = {};
        continue;
      }
      if (t.first_gap_seen == Clock::time_point{}) t.first_gap_seen = now;
      if (now - t.first_gap_seen < options.resend_grace) continue;
      for (const FrameRange& gap : gaps) {
        auto asked = t.asked.find(gap.first);
        if (asked != t.asked.end() && now - asked->second < options.resend_interval) continue;
        RequestResend(t, gap.first, std::min(gap.last, gap.first + options.max_resend_frames - 1));
        t.asked[gap.first] = now;
      }
    }
  }
};

IngestService::IngestService(IngestOptions options)
    : impl_(std::make_unique<Impl>(std::move(options))) {}
IngestService::~IngestService() = default;

void IngestService::Open() {
  Impl& s = *impl_;
  s.store.Open();
  for (const std::string& id : s.store.Cameras()) {
    const std::vector<uint32_t> sessions = s.store.Sessions(id);
    if (sessions.empty()) continue;
    Impl::Track& t = s.TrackFor(id);
    s.StartSession(t, sessions.back());
  }
  s.participant = std::make_unique<dds::Participant>(s.options.domain);
  s.hull_topic = std::make_unique<dds::Topic<silnet_wire_HullFrame>>(*s.participant);
  s.contour_topic = std::make_unique<dds::Topic<silnet_wire_Contour>>(*s.participant);
  s.info_topic = std::make_unique<dds::Topic<silnet_wire_CameraInfo>>(*s.participant);
  s.status_topic = std::make_unique<dds::Topic<silnet_wire_NodeStatus>>(*s.participant);
  s.command_topic = std::make_unique<dds::Topic<silnet_wire_Command>>(*s.participant);
  s.hull_reader =
      std::make_unique<dds::Reader<silnet_wire_HullFrame>>(*s.hull_topic, s.options.qos);
  s.contour_reader =
      std::make_unique<dds::Reader<silnet_wire_Contour>>(*s.contour_topic, s.options.qos);
  s.info_reader =
      std::make_unique<dds::Reader<silnet_wire_CameraInfo>>(*s.info_topic, s.options.qos);
  s.status_reader =
      std::make_unique<dds::Reader<silnet_wire_NodeStatus>>(*s.status_topic, s.options.qos);
  s.command_writer =
      std::make_unique<dds::Writer<silnet_wire_Command>>(*s.command_topic, s.options.qos);
}

size_t IngestService::Poll(std::chrono::milliseconds wait) {
  Impl& s = *impl_;
  s.hull_reader->WaitForData(wait);
  size_t handled = 0;
  handled += s.hull_reader->Take([&](const silnet_wire_HullFrame& sample,
                                     const dds_sample_info_t&) { s.OnHull(dds::FromWire(sample)); },
                                 100000);
  handled +=
      s.contour_reader->Take([&](const silnet_wire_Contour& sample,
                                 const dds_sample_info_t&) { s.OnContour(dds::FromWire(sample)); },
                             100000);
  handled +=
      s.info_reader->Take([&](const silnet_wire_CameraInfo& sample, const dds_sample_info_t&) {
        const CameraInfoRecord info = dds::FromWire(sample);
        if (info.camera_id.empty()) return;
        s.store.AddCameraInfo(info);
        Impl::Track& t = s.TrackFor(info.camera_id);
        const auto every = info.parameters.find("contour_every");
        if (every == info.parameters.end()) return;
        const int before = t.contour_every;
        t.contour_every = std::atoi(every->second.c_str());
        if (t.contour_every != before) s.ScheduleMissingContours(t);
      });
  handled +=
      s.status_reader->Take([&](const silnet_wire_NodeStatus& sample, const dds_sample_info_t&) {
        const std::string id = dds::ReadBoundedString(sample.camera_id);
        if (id.empty()) return;
        Impl::Track& t = s.TrackFor(id);
        if (sample.session != t.status.session) return;  // another session's counts
        t.status.node_state = dds::ReadBoundedString(sample.state);
        t.status.node_fps = sample.fps;
        if (t.status.node_state.starts_with("running")) {
          ++t.cpu_statuses;
          t.status.node_cpu_percent += (sample.cpu_percent - t.status.node_cpu_percent) /
                                       static_cast<double>(t.cpu_statuses);
        }
        t.status.node_published = sample.frames_published;
        t.status.node_dropped = sample.frames_dropped;
        t.status.node_flagged = sample.frames_flagged;
        t.last_status = Clock::now();
      });
  s.DetectStalls();
  s.RequestMissing();
  return handled;
}

std::vector<CameraIngestStatus> IngestService::Status() const {
  std::vector<CameraIngestStatus> out;
  for (const auto& [id, t] : impl_->tracks)
    out.push_back(impl_->Snapshot(t, true));
  return out;
}

IngestTotals IngestService::Totals() const {
  IngestTotals totals;
  totals.malformed = impl_->malformed_unknown;
  for (const auto& [id, t] : impl_->tracks)
    totals.contours_overdue += t.contour_due.size();
  if (impl_->hull_reader) {
    const dds::ReaderCounters hull = impl_->hull_reader->Counters(),
                              contour = impl_->contour_reader->Counters();
    totals.dds_samples_lost = hull.samples_lost + contour.samples_lost;
    totals.dds_samples_rejected = hull.samples_rejected + contour.samples_rejected;
  }
  for (const auto& [id, t] : impl_->tracks) {
    const CameraIngestStatus c = impl_->Snapshot(t, false);
    totals.received += c.received;
    totals.stored += c.frames_held;
    totals.duplicates += c.duplicates;
    totals.malformed += c.malformed;
    totals.out_of_order += c.out_of_order;
    totals.resend_requests += c.resend_requests;
    totals.missing += c.missing;
    totals.store_failures += c.store_failures;
    totals.stalls += c.stalls;
    totals.cameras_stalled += c.stalled ? 1 : 0;
    totals.node_dropped += c.node_dropped;
    totals.node_flagged += c.node_flagged;
  }
  return totals;
}

void IngestService::Flush() {
  impl_->store.Flush();
}

void IngestService::WriteSummary(const std::filesystem::path& path) const {
  ReplaceYaml(path, [&](cv::FileStorage& fs) {
    fs << "cameras"
       << "[";
    for (const CameraIngestStatus& c : Status()) {
      fs << "{"
         << "id" << c.camera_id << "session" << static_cast<int>(c.session) << "frames_held"
         << static_cast<double>(c.frames_held) << "first_frame"
         << static_cast<double>(c.first_frame) << "last_frame" << static_cast<double>(c.last_frame)
         << "missing" << static_cast<double>(c.missing) << "received"
         << static_cast<double>(c.received) << "contours" << static_cast<double>(c.contours)
         << "duplicates" << static_cast<double>(c.duplicates) << "out_of_order"
         << static_cast<double>(c.out_of_order) << "malformed" << static_cast<double>(c.malformed)
         << "resend_requests" << static_cast<double>(c.resend_requests) << "resent_received"
         << static_cast<double>(c.resent_received) << "store_failures"
         << static_cast<double>(c.store_failures) << "stalls" << static_cast<double>(c.stalls)
         << "latency_median_ms" << c.latency_median_ms << "latency_p99_ms" << c.latency_p99_ms
         << "node_cpu_percent" << c.node_cpu_percent << "node_state" << c.node_state << "node_alive"
         << static_cast<int>(c.node_alive) << "node_fps" << c.node_fps << "node_dropped"
         << static_cast<double>(c.node_dropped) << "node_flagged"
         << static_cast<double>(c.node_flagged) << "seconds_since_last_frame"
         << c.seconds_since_last << "stalled" << static_cast<int>(c.stalled) << "}";
    }
    fs << "]";
    const IngestTotals totals = Totals();
    fs << "malformed_without_camera" << static_cast<double>(impl_->malformed_unknown);
    fs << "contours_overdue" << static_cast<double>(totals.contours_overdue);
    fs << "dds_samples_lost" << static_cast<double>(totals.dds_samples_lost);
    fs << "dds_samples_rejected" << static_cast<double>(totals.dds_samples_rejected);
  });
}

}  // namespace silnet::aggregator
