#include "aggregator/ingest/still_views.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "aggregator/stereo/silhouette_consensus.h"
#include "node/segmentation/weak_silhouette.h"
#include "shared/util/check.h"
#include "silnet.h"

namespace silnet::aggregator {

uint64_t FirstFrameAtOrAfter(const CameraModel& camera, double t) {
  const double k = std::ceil(t * camera.fps - camera.time_offset - 1e-9);
  return k > 0 ? static_cast<uint64_t>(k) : 0;
}

StereoViews StillViews(const StillCollection& collection, const std::vector<CameraModel>& cameras) {
  StereoViews views;
  for (const CollectedStill& still : collection.cameras) {
    if (!still.complete) {
      views.warnings.push_back(
          fmt::format("{}: no still ({}), left out", still.camera_id, still.reason));
      continue;
    }
    const auto camera = std::find_if(cameras.begin(), cameras.end(),
                                     [&](const CameraModel& c) { return c.id == still.camera_id; });
    if (camera == cameras.end()) {
      views.warnings.push_back(
          fmt::format("{}: not in the calibration, left out", still.camera_id));
      continue;
    }
    constexpr uint32_t kUnreliable = silnet_wire_FRAME_WARMUP | silnet_wire_FRAME_SATURATED |
                                     silnet_wire_FRAME_BAD_INPUT | silnet_wire_FRAME_EMPTY;
    if (still.frame_flags & silnet_wire_FRAME_WARMUP) {
      views.warnings.push_back(fmt::format(
          "{}: its silhouette is from the background model's warm-up, left out (ask later)",
          still.camera_id));
      continue;
    }
    if (still.frame_flags & kUnreliable) {
      views.warnings.push_back(
          fmt::format("{}: its node flagged the silhouette unusable, left out", still.camera_id));
      continue;
    }
    if (cv::countNonZero(still.silhouette == 255) == 0) {
      views.warnings.push_back(fmt::format("{}: empty silhouette, left out", still.camera_id));
      continue;
    }
    StereoView view;
    try {
      view.camera = CameraAtImageSize(*camera, still.photo.cols, still.photo.rows);
    } catch (const InputError& e) {
      views.warnings.push_back(
          fmt::format("{}: the still is {}, left out", still.camera_id, e.what()));
      continue;
    }
    view.image = still.photo;
    view.mask = still.silhouette;
    view.silhouette_source = MaskOrigin::kMaskFile;
    views.views.push_back(std::move(view));
  }
  // Weak evidence beside the silhouettes, kept where the other views confirm it.
  const SilhouetteConsensus consensus = ResolveWeakSilhouettes(&views.views, node::kWeakSilhouette);
  if (consensus.candidates > 0) {
    spdlog::info("stills: {} of {} weak silhouette pixels confirmed by the other views",
                 consensus.kept, consensus.candidates);
  }
  return views;
}

void WriteStillSummary(const std::filesystem::path& path, const StillCollection& collection) {
  cv::FileStorage out(path.string(), cv::FileStorage::WRITE);
  if (!out.isOpened()) throw InputError("cannot write " + path.string());
  out << "still_id" << std::to_string(collection.still_id);
  out << "seconds" << collection.seconds;
  out << "complete" << static_cast<int>(collection.complete());
  out << "cameras"
      << "[";
  for (const CollectedStill& c : collection.cameras) {
    out << "{";
    out << "id" << c.camera_id << "complete" << static_cast<int>(c.complete);
    if (!c.complete) out << "reason" << c.reason;
    if (c.complete) {
      out << "frame_index" << std::to_string(c.frame_index);
      out << "frame_flags" << static_cast<int>(c.frame_flags);
      out << "capture_time_ns" << std::to_string(c.capture_time_ns);
      out << "width" << c.photo.cols << "height" << c.photo.rows;
      out << "photo_encoding" << c.photo_encoding;
    }
    out << "chunks_accepted" << static_cast<int>(c.chunks.accepted);
    out << "chunks_duplicate" << static_cast<int>(c.chunks.duplicates);
    out << "chunks_corrupt" << static_cast<int>(c.chunks.corrupt);
    out << "chunks_malformed" << static_cast<int>(c.chunks.malformed);
    out << "capture_requests" << static_cast<int>(c.requests);
    out << "resend_requests" << static_cast<int>(c.resend_requests);
    out << "bad_images" << static_cast<int>(c.bad_images);
    out << "}";
  }
  out << "]";
}

}  // namespace silnet::aggregator
