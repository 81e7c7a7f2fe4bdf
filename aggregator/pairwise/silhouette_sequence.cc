#include "aggregator/pairwise/silhouette_sequence.h"

#include <spdlog/spdlog.h>

#include <opencv2/imgcodecs.hpp>

#include "aggregator/ingest/session_store.h"
#include "node/capture/files/video_file_source.h"
#include "node/pipeline/frame_processor.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#include "shared/io/session_log.h"
#include "shared/silhouette/hull_codec.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"
#include "silnet.h"

namespace silnet::aggregator {
namespace {

constexpr uint32_t kUnusable = silnet_wire_FRAME_EMPTY | silnet_wire_FRAME_SATURATED |
                               silnet_wire_FRAME_BAD_INPUT | silnet_wire_FRAME_DROPPED;

std::vector<SilhouetteSequence> FromSessionLogs(const std::filesystem::path& dir,
                                                const SequenceLoadOptions& options) {
  std::vector<SilhouetteSequence> out;
  for (const std::string& id : SessionLogCameras(dir)) {
    SessionReadReport report;
    std::vector<SessionFrames> sessions = ReadSessionLog(SessionLogPath(dir, id), &report);
    if (!report.problem.empty()) spdlog::warn("{}: {}", id, report.problem);
    if (sessions.empty()) continue;
    const SessionFrames& s = sessions.back();
    SilhouetteSequence seq;
    seq.camera_id = id;
    seq.allow_warmup = options.allow_warmup;
    seq.fps = s.info.nominal_fps > 0 ? s.info.nominal_fps : 30.0;
    for (const FrameRecord& record : s.hulls) {
      if (record.frame_index < static_cast<uint64_t>(std::max(options.first_frame, 0))) continue;
      if (options.max_frames > 0 && static_cast<int>(seq.frames.size()) >= options.max_frames)
        break;
      seq.width = record.width;
      seq.height = record.height;
      seq.frames.push_back(DecodeSilhouetteFrame(record));
    }
    seq.Index();
    out.push_back(std::move(seq));
  }
  return out;
}

// Runs a camera's images, read one by one by `read` (an empty image ends the sequence),
// through the node's own per-frame pipeline and decodes what it encoded, so the wire format
// is exercised exactly as live.
template <typename ReadImage>
SilhouetteSequence EncodeCamera(const std::string& id, bool masks, int first_frame, int count,
                                double fps, bool allow_warmup, ReadImage&& read) {
  SilhouetteSequence seq;
  seq.camera_id = id;
  seq.fps = fps;
  seq.allow_warmup = allow_warmup || masks;
  std::unique_ptr<node::FrameProcessor> processor;
  for (int k = 0; count < 0 || k < count; ++k) {
    const int frame = first_frame + k;
    const cv::Mat image = read(frame);
    if (image.empty()) break;
    if (!processor) {
      node::FrameProcessorOptions o;
      o.camera_id = id;
      o.contour_every = 0;
      if (masks) o.segmentation.method = node::SegmentationMethod::kMaskInput;
      processor = std::make_unique<node::FrameProcessor>(o, image.cols, image.rows);
      seq.width = image.cols;
      seq.height = image.rows;
    }
    node::CapturedFrame captured;
    captured.image = image;
    captured.frame_index = static_cast<uint64_t>(frame);
    captured.capture_time_ns = static_cast<int64_t>(frame / fps * 1e9);
    seq.frames.push_back(DecodeSilhouetteFrame(processor->Process(captured).hull));
  }
  seq.Index();
  return seq;
}

SilhouetteSequence FromDatasetCamera(const DatasetLayout& layout, const std::string& id, bool masks,
                                     const SequenceLoadOptions& options, double fps) {
  int count = layout.CountImages(id, masks ? "masks" : "frames") - options.first_frame;
  if (options.max_frames > 0) count = std::min(count, options.max_frames);
  return EncodeCamera(
      id, masks, options.first_frame, std::max(count, 0), fps, options.allow_warmup,
      [&](int frame) {
        const auto path = masks ? layout.MaskPath(id, frame) : layout.FramePath(id, frame);
        cv::Mat image = cv::imread(path.string(), masks ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
        if (image.empty()) throw InputError(path.string() + ": cannot read image");
        return image;
      });
}

// A camera's video (masks, or colour frames to segment), decoded by the node's video file
// source.
SilhouetteSequence FromVideo(const DatasetLayout& layout, const std::string& id,
                             const std::string& file, bool masks,
                             const SequenceLoadOptions& options) {
  node::VideoFileSourceOptions video;
  video.file = layout.CameraDir(id) / file;
  video.fps = options.video_fps;
  video.first_frame = static_cast<uint64_t>(std::max(options.first_frame, 0));
  video.max_frames = static_cast<uint64_t>(std::max(options.max_frames, 0));
  node::VideoFileSource source(video);
  try {
    source.Open();
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  const double fps = source.Format().fps > 0 ? source.Format().fps : 30.0;
  // An undecodable frame becomes an empty silhouette, so later frames keep their index.
  size_t errors = 0;
  const cv::Size size(source.Format().width, source.Format().height);
  SilhouetteSequence seq = EncodeCamera(
      id, masks, options.first_frame, -1, fps, options.allow_warmup, [&](int) -> cv::Mat {
        node::CapturedFrame frame;
        const node::CaptureStatus status = source.Read(&frame, std::chrono::milliseconds(0));
        if (status == node::CaptureStatus::kFrame) return frame.image;
        if (status != node::CaptureStatus::kFrameError || size.area() == 0) return {};
        ++errors;
        return cv::Mat::zeros(size, masks ? CV_8UC1 : CV_8UC3);
      });
  if (errors > 0) spdlog::warn("{}: {} undecodable frames skipped", video.file.string(), errors);
  if (seq.frames.empty()) throw InputError(video.file.string() + ": no frame decoded");
  return seq;
}

}  // namespace

SilhouetteFrame DecodeSilhouetteFrame(const FrameRecord& record) {
  SilhouetteFrame frame;
  frame.index = record.frame_index;
  frame.capture_time_ns = record.capture_time_ns;
  frame.flags = record.flags;
  HullPayload payload;
  std::string error;
  if (!DecodeHull(record.payload, record.width, record.height, &payload, &error)) {
    frame.flags |= silnet_wire_FRAME_BAD_INPUT;
  } else {
    frame.hull = std::move(payload.hull);
  }
  return frame;
}

const SilhouetteFrame* SilhouetteSequence::Usable(uint64_t index) const {
  if (frames.empty() || index < first_index() || index > last_index()) return nullptr;
  const int32_t p = position_[index - first_index()];
  if (p < 0) return nullptr;
  const SilhouetteFrame& f = frames[static_cast<size_t>(p)];
  if ((f.flags & kUnusable) || f.hull.size() < 3) return nullptr;
  if (!allow_warmup && (f.flags & silnet_wire_FRAME_WARMUP)) return nullptr;
  return &f;
}

size_t SilhouetteSequence::UsableCount() const {
  size_t count = 0;
  for (const SilhouetteFrame& f : frames)
    count += Usable(f.index) != nullptr ? 1 : 0;
  return count;
}

void SilhouetteSequence::Index() {
  position_.assign(frames.empty() ? 0 : last_index() - first_index() + 1, -1);
  for (size_t i = 0; i < frames.size(); ++i) {
    position_[frames[i].index - first_index()] = static_cast<int32_t>(i);
  }
}

std::vector<SilhouetteSequence> LoadSequences(const std::filesystem::path& input,
                                              const SequenceLoadOptions& options,
                                              SequenceSource* detected) {
  if (!std::filesystem::is_directory(input)) throw InputError(input.string() + ": not a folder");
  for (const std::filesystem::path& dir : {input, input / "sessions"}) {
    if (!SessionLogCameras(dir).empty()) {
      if (detected != nullptr) *detected = SequenceSource::kSessionLogs;
      return FromSessionLogs(dir, options);
    }
  }
  const DatasetLayout layout(input);
  if (!options.mask_video.empty() && !options.frame_video.empty())
    throw InputError("give either a mask video or a colour video per camera, not both");
  if (!options.mask_video.empty() || !options.frame_video.empty()) {
    const bool masks = !options.mask_video.empty();
    const std::string& file = masks ? options.mask_video : options.frame_video;
    const std::vector<std::string> ids = layout.CameraIdsWithFile(file);
    if (ids.empty()) {
      throw InputError(input.string() + ": no camera folder holds a video named " + file);
    }
    if (detected != nullptr)
      *detected = masks ? SequenceSource::kMaskVideo : SequenceSource::kFrameVideo;
    std::vector<SilhouetteSequence> out(ids.size());
    ParallelFor(ids.size(), options.threads,
                [&](size_t i) { out[i] = FromVideo(layout, ids[i], file, masks, options); });
    return out;
  }
  const std::vector<std::string> ids = layout.CameraIds();
  if (ids.empty()) {
    throw InputError(
        input.string() +
        ": holds neither session logs (*.silnetlog) nor camera folders with masks/ or frames/");
  }
  // Frame rates from the ground truth when there is one (the dataset's own description).
  std::map<std::string, double> fps;
  if (std::filesystem::exists(layout.GroundTruthPath())) {
    for (const CameraModel& c : LoadCalibration(layout.GroundTruthPath()))
      fps[c.id] = c.fps;
  }
  const bool masks = layout.CountImages(ids[0], "masks") > 0;
  if (detected != nullptr)
    *detected = masks ? SequenceSource::kMaskDataset : SequenceSource::kFrameDataset;
  std::vector<SilhouetteSequence> out(ids.size());
  ParallelFor(ids.size(), options.threads, [&](size_t i) {
    const auto rate = fps.find(ids[i]);
    out[i] =
        FromDatasetCamera(layout, ids[i], masks, options, rate == fps.end() ? 30.0 : rate->second);
  });
  return out;
}

}  // namespace silnet::aggregator
