#include "node/capture/files/video_file_source.h"

#include <fmt/format.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio/registry.hpp>
#include <system_error>
#include <utility>

#include "shared/util/check.h"

namespace silnet::node {
namespace {

// The container's codec as four characters ("MJPG"), or "" if unknown.
std::string FourccText(double value) {
  if (!std::isfinite(value) || value < 1.0 || value > 4294967295.0) return "";
  const auto fourcc = static_cast<uint32_t>(value);
  std::string text;
  for (int shift = 0; shift < 32; shift += 8) {
    const char c = static_cast<char>((fourcc >> shift) & 0xFF);
    text.push_back(c >= 32 && c < 127 ? c : '?');
  }
  return text;
}

// OpenCV backends that decode video files, in order of preference.
constexpr cv::VideoCaptureAPIs kFileBackends[] = {cv::CAP_FFMPEG, cv::CAP_GSTREAMER,
                                                  cv::CAP_OPENCV_MJPEG};

std::string FpsText(double fps) {
  return fps > 0.0 ? fmt::format("{:g} fps", fps) : "fps unknown";
}

}  // namespace

VideoFileSource::VideoFileSource(VideoFileSourceOptions options) : options_(std::move(options)) {}

void VideoFileSource::Open() {
  Close();
  const std::string name = options_.file.string();
  CheckReplayOptions(options_, "video file " + name);
  std::error_code error;
  if (!std::filesystem::is_regular_file(options_.file, error))
    throw CaptureError(fmt::format("video file {} does not exist or is not a file", name));
  // Only backends that read files: CAP_ANY would also try camera backends (gPhoto2 probes
  // every USB device for each file name, slowly, and leaks doing so).
  std::string tried;
  for (const cv::VideoCaptureAPIs api : kFileBackends) {
    if (!cv::videoio_registry::hasBackend(api)) continue;
    const std::string backend = cv::videoio_registry::getBackendName(api);
    tried += (tried.empty() ? "" : ", ") + backend;
    try {
      if (capture_.open(name, api) && capture_.isOpened()) {
        backend_ = backend;
        break;
      }
    } catch (const cv::Exception&) {
      capture_.release();
    }
  }
  if (!capture_.isOpened())
    throw CaptureError(
        fmt::format("cannot open video file {}: none of OpenCV's file backends ({}) "
                    "can decode it",
                    name, tried.empty() ? "none installed" : tried));

  codec_ = FourccText(capture_.get(cv::CAP_PROP_FOURCC));
  format_ = CaptureFormat{};
  format_.pixel_format = "BGR";
  format_.fps = options_.fps;
  if (format_.fps == 0.0) {
    const double container_fps = capture_.get(cv::CAP_PROP_FPS);
    if (std::isfinite(container_fps) && container_fps > 0.0) format_.fps = container_fps;
  }
  if (options_.real_time && format_.fps <= 0.0) {
    Close();
    throw CaptureError(fmt::format(
        "video file {}: real-time replay needs a frame rate and the file states none", name));
  }

  for (uint64_t skipped = 0; skipped < options_.first_frame; ++skipped) {
    if (!capture_.grab()) {
      Close();
      throw CaptureError(fmt::format("video file {} has {} frames; first frame {} is past the end",
                                     name, skipped, options_.first_frame));
    }
  }

  format_.width = options_.width;
  format_.height = options_.height;
  if (format_.width == 0) {
    const double width = capture_.get(cv::CAP_PROP_FRAME_WIDTH);
    const double height = capture_.get(cv::CAP_PROP_FRAME_HEIGHT);
    if (std::isfinite(width) && std::isfinite(height) && width >= 1.0 && height >= 1.0) {
      format_.width = static_cast<int>(width);
      format_.height = static_cast<int>(height);
    }
  }
  open_ = true;
  // Without a stated size the first frame sets it; it stays pending for the first Read().
  if (format_.width == 0 && DecodeNext() && pending_->error.empty()) {
    format_.width = pending_->image.cols;
    format_.height = pending_->image.rows;
  }

  if (format_.fps > 0.0) {
    const int64_t start = options_.start_ns != 0 ? options_.start_ns : RealtimeNowNs();
    pacer_.emplace(format_.fps, start, options_.offset_frames);
  }
}

bool VideoFileSource::DecodeNext() {
  if (ended_ || (options_.max_frames > 0 && decoded_ >= options_.max_frames)) {
    ended_ = true;
    return false;
  }
  cv::Mat image;
  bool decoded = false;
  try {
    decoded = capture_.read(image);
  } catch (const cv::Exception&) {
    decoded = false;
  }
  if (!decoded || image.empty()) {
    ended_ = true;
    return false;
  }
  pending_ = Make(decoded_, std::move(image));
  ++decoded_;
  return true;
}

ReplayedFrame VideoFileSource::Make(uint64_t delivered, cv::Mat image) const {
  ReplayedFrame pending;
  pending.position = delivered;
  const uint64_t index = options_.first_frame + delivered;
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4)) {
    pending.error = fmt::format("video file {}: frame {} has unsupported pixel type {}",
                                options_.file.string(), index, cv::typeToString(image.type()));
  } else if (format_.width != 0 && (image.cols != format_.width || image.rows != format_.height)) {
    pending.error =
        fmt::format("video file {}: frame {} is {}x{}, expected {}x{}", options_.file.string(),
                    index, image.cols, image.rows, format_.width, format_.height);
  } else if (image.channels() == 1) {
    cv::cvtColor(image, pending.image, cv::COLOR_GRAY2BGR);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, pending.image, cv::COLOR_BGRA2BGR);
  } else {
    pending.image = std::move(image);
  }
  return pending;
}

CaptureStatus VideoFileSource::Read(CapturedFrame* frame, std::chrono::milliseconds timeout) {
  SILNET_CHECK_MSG(open_, "VideoFileSource::Read() before Open()");
  SILNET_CHECK(frame != nullptr);
  if (!pending_ && !DecodeNext()) return CaptureStatus::kEndOfStream;
  return DeliverReplayedFrame(&pending_, pacer_, options_.real_time, options_.first_frame, timeout,
                              frame, &counters_, &last_error_);
}

void VideoFileSource::Close() {
  open_ = false;
  ended_ = false;
  decoded_ = 0;
  pending_.reset();
  pacer_.reset();
  capture_.release();
  backend_.clear();
}

std::string VideoFileSource::Describe() const {
  return fmt::format("video:{} {}x{} {} ({} via {}) {}", options_.file.string(), format_.width,
                     format_.height, format_.pixel_format,
                     codec_.empty() ? "codec unknown" : codec_,
                     backend_.empty() ? "no backend" : backend_, FpsText(format_.fps));
}

}  // namespace silnet::node
