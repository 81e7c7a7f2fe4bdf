#include "node/capture/v4l2/v4l2_source.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>
#include <thread>
#include <utility>

#include "shared/util/check.h"

namespace silnet::node {
namespace {

constexpr int kMaxBuffers = 32;
// Buffers streamed while taking a still (few: the frames are large).
constexpr int kStillBuffers = 2;
// Bad frames (error-flagged, corrupt) skipped before a still fails.
constexpr int kMaxBadStillFrames = 3;
// Most settle frames an option may ask for.
constexpr int kMaxSettleFrames = 1000;
// Most VIDIOC_ENUM_FRAMESIZES entries looked at per pixel format (guards a looping driver).
constexpr uint32_t kMaxFrameSizeEntries = 4096;

// A V4L2 four-character code as text ("YUYV").
std::string FourccText(uint32_t fourcc) {
  std::string text;
  for (int shift = 0; shift < 32; shift += 8) {
    const char c = static_cast<char>((fourcc >> shift) & 0xFF);
    text.push_back(c >= 32 && c < 127 ? c : '?');
  }
  return text;
}

bool IsDecodable(uint32_t pixel_format) {
  return pixel_format == V4L2_PIX_FMT_YUYV || pixel_format == V4L2_PIX_FMT_MJPEG ||
         pixel_format == V4L2_PIX_FMT_JPEG;
}

std::string FpsText(double fps) {
  return fps > 0.0 ? fmt::format("{:g} fps", fps) : "fps unknown";
}

std::string ErrnoText(int error) {
  return std::generic_category().message(error);
}

// The reason open(2) failed, with a hint for the usual causes.
std::string OpenErrorText(int error) {
  switch (error) {
    case ENOENT:
    case ENODEV:
    case ENXIO:
      return fmt::format("{} (is the camera connected?)", ErrnoText(error));
    case EACCES:
    case EPERM:
      return fmt::format("{} (is the user in the 'video' group?)", ErrnoText(error));
    case EBUSY:
      return fmt::format("{} (is another program using the camera?)", ErrnoText(error));
    default:
      return ErrnoText(error);
  }
}

int64_t MonotonicNowNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<int64_t>(now.tv_sec) * 1000000000LL + now.tv_nsec;
}

// Milliseconds left until `deadline`, rounded up, in [0, INT_MAX].
int TimeoutMs(std::chrono::steady_clock::time_point deadline) {
  const auto left = deadline - std::chrono::steady_clock::now();
  if (left <= std::chrono::steady_clock::duration::zero()) return 0;
  const auto ms = std::chrono::ceil<std::chrono::milliseconds>(left).count();
  return static_cast<int>(std::min<int64_t>(ms, INT_MAX));
}

// `fps` as a V4L2 frame interval (seconds per frame), to a thousandth of a frame per second.
v4l2_fract FrameInterval(double fps) {
  const auto per_thousand_seconds = static_cast<uint32_t>(std::llround(fps * 1000.0));
  const uint32_t divisor = std::gcd(1000u, per_thousand_seconds);
  v4l2_fract interval{};
  interval.numerator = 1000u / divisor;
  interval.denominator = per_thousand_seconds / divisor;
  return interval;
}

// Frames per second of a V4L2 frame interval; 0 if it is not set.
double FpsOf(const v4l2_fract& interval) {
  if (interval.numerator == 0 || interval.denominator == 0) return 0.0;
  return static_cast<double>(interval.denominator) / interval.numerator;
}

// True if `data` starts with a JPEG start-of-image marker and holds an end-of-image marker.
// Inside entropy-coded data 0xFF is only followed by 0x00 or a restart marker, so a frame cut
// short has no 0xFF 0xD9; drivers may pad after the marker, hence the search from the end.
bool JpegLooksComplete(const uint8_t* data, size_t size) {
  if (size < 4 || data[0] != 0xFF || data[1] != 0xD8) return false;
  for (size_t i = size - 1; i >= 3; --i) {
    if (data[i] == 0xD9 && data[i - 1] == 0xFF) return true;
  }
  return false;
}

// True if width x height has the aspect ratio of video_width x video_height within 1 %.
bool SameAspect(int64_t width, int64_t height, int64_t video_width, int64_t video_height) {
  if (width <= 0 || height <= 0 || video_width <= 0 || video_height <= 0) return false;
  const double aspect = static_cast<double>(width) / static_cast<double>(height);
  const double video_aspect = static_cast<double>(video_width) / static_cast<double>(video_height);
  return std::abs(aspect - video_aspect) <= 0.01 * video_aspect;
}

// A frame size a device offers.
struct FrameSize {
  int64_t width = 0;
  int64_t height = 0;
  int64_t area() const { return width * height; }
};

// The largest size of the range min + k * step (per axis, within max) of the aspect ratio of
// `video` within 1 %; a zero area if none. For each width the nearest heights on the grid to
// the exact aspect ratio are tried; widths go down while they can still give a larger area.
FrameSize LargestOfAspectInRange(const v4l2_frmsize_stepwise& range, const FrameSize& video) {
  FrameSize best;
  const int64_t min_w = range.min_width, max_w = range.max_width;
  const int64_t min_h = range.min_height, max_h = range.max_height;
  const int64_t step_w = std::max<int64_t>(1, range.step_width);
  const int64_t step_h = std::max<int64_t>(1, range.step_height);
  if (min_w <= 0 || min_h <= 0 || max_w < min_w || max_h < min_h) return best;
  const int64_t last_h = (max_h - min_h) / step_h;
  for (int64_t k = (max_w - min_w) / step_w; k >= 0; --k) {
    const int64_t width = min_w + k * step_w;
    if (width * max_h <= best.area()) break;
    const double ideal = static_cast<double>(width) * static_cast<double>(video.height) /
                         static_cast<double>(video.width);
    const auto below = static_cast<int64_t>(
        std::floor((ideal - static_cast<double>(min_h)) / static_cast<double>(step_h)));
    for (int64_t j = below + 1; j >= below; --j) {
      if (j < 0 || j > last_h) continue;
      const FrameSize candidate{width, min_h + j * step_h};
      if (SameAspect(candidate.width, candidate.height, video.width, video.height) &&
          candidate.area() > best.area()) {
        best = candidate;
        break;
      }
    }
  }
  return best;
}

}  // namespace

V4l2Source::V4l2Source(V4l2SourceOptions options, std::unique_ptr<V4l2Device> device)
    : options_(std::move(options)), device_(std::move(device)) {
  SILNET_CHECK_MSG(device_ != nullptr, "V4l2Source needs a device");
  if (options_.device.empty()) throw CaptureError("v4l2: no device node given");
  if (options_.width <= 0 || options_.height <= 0)
    throw CaptureError(DeviceMessage(
        fmt::format("frame size must be positive (got {}x{})", options_.width, options_.height)));
  if (!std::isfinite(options_.fps) || options_.fps <= 0.0 || options_.fps > 100000.0)
    throw CaptureError(DeviceMessage(fmt::format("bad frame rate {}", options_.fps)));
  if (options_.buffer_count < 1 || options_.buffer_count > kMaxBuffers)
    throw CaptureError(DeviceMessage(
        fmt::format("buffer count must be 1..{} (got {})", kMaxBuffers, options_.buffer_count)));
  if (options_.reopen_interval.count() < 0)
    throw CaptureError(DeviceMessage("the reopen interval must not be negative"));
  if (options_.still_settle_frames < 0 || options_.still_settle_frames > kMaxSettleFrames)
    throw CaptureError(DeviceMessage(fmt::format("still settle frames must be 0..{} (got {})",
                                                 kMaxSettleFrames, options_.still_settle_frames)));
  if (options_.still_timeout.count() <= 0)
    throw CaptureError(DeviceMessage("the still timeout must be positive"));
  description_ = fmt::format("v4l2:{} (not open)", options_.device);
}

V4l2Source::~V4l2Source() {
  Close();
}

void V4l2Source::Open() {
  Close();
  have_last_ = false;
  resync_ = false;
  OpenDevice();
  state_ = State::kStreaming;
  opened_once_ = true;
  UpdateDescription();
  {
    std::lock_guard lock(mutex_);
    accepting_stills_ = true;
  }
  spdlog::info("opened {}", Describe());
}

void V4l2Source::Close() {
  ReleaseDevice();
  state_ = State::kClosed;
  {
    std::lock_guard lock(mutex_);
    accepting_stills_ = false;
    pending_still_.reset();
    if (waiting_still_id_ != 0) {
      still_answer_ = StillAnswer{waiting_still_id_, cv::Mat(),
                                  DeviceMessage("the source was closed while a still waited")};
    }
  }
  still_answered_.notify_all();
}

std::string V4l2Source::Describe() const {
  std::lock_guard lock(mutex_);
  return description_;
}

void V4l2Source::UpdateDescription() {
  std::string text = fmt::format("v4l2:{} {}x{} {} {}", options_.device, format_.width,
                                 format_.height, format_.pixel_format, FpsText(format_.fps));
  std::lock_guard lock(mutex_);
  description_ = std::move(text);
}

std::string V4l2Source::DeviceMessage(const std::string& message) const {
  return fmt::format("v4l2:{}: {}", options_.device, message);
}

void V4l2Source::ThrowCallError(const std::string& what, int error) const {
  std::string reason = ErrnoText(error);
  if (error == EBUSY) reason += " (is another program using the camera?)";
  throw CaptureError(DeviceMessage(fmt::format("{} failed: {}", what, reason)));
}

void V4l2Source::OpenDevice() {
  fd_ = device_->Open(options_.device, O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int error = errno;
    fd_ = -1;
    throw CaptureError(DeviceMessage(fmt::format("cannot open: {}", OpenErrorText(error))));
  }
  try {
    CheckCapabilities();
    NegotiateFormat();
    if (options_.full_resolution_stills) {
      std::optional<StillTarget> target = FindStillTarget();
      if (target) {
        spdlog::info("{}",
                     DeviceMessage(fmt::format("stills at {}x{} {}", target->width, target->height,
                                               FourccText(target->pixel_format))));
      } else {
        spdlog::info("{}", DeviceMessage("no larger frame size of the video's aspect ratio: "
                                         "stills at the video size"));
      }
      std::lock_guard lock(mutex_);
      still_target_ = target;
    }
    StartStreaming(options_.buffer_count);
  } catch (...) {
    ReleaseDevice();
    throw;
  }
}

void V4l2Source::CheckCapabilities() {
  v4l2_capability capability{};
  if (device_->Ioctl(fd_, VIDIOC_QUERYCAP, &capability) < 0) {
    const int error = errno;
    if (error == ENOTTY || error == EINVAL)
      throw CaptureError(DeviceMessage("not a V4L2 device (VIDIOC_QUERYCAP is not supported)"));
    ThrowCallError("VIDIOC_QUERYCAP", error);
  }
  const uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0
                            ? capability.device_caps
                            : capability.capabilities;
  const auto* card_bytes = reinterpret_cast<const char*>(capability.card);
  const std::string card(card_bytes, strnlen(card_bytes, sizeof(capability.card)));
  if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
    const char* hint = (caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0
                           ? " (multi-planar capture devices are not supported)"
                           : "";
    throw CaptureError(
        DeviceMessage(fmt::format("'{}' is not a video capture device{}", card, hint)));
  }
  if ((caps & V4L2_CAP_STREAMING) == 0)
    throw CaptureError(DeviceMessage(fmt::format("'{}' does not support streaming I/O", card)));
}

V4l2Source::Negotiated V4l2Source::Negotiate(uint32_t pixel_format) {
  Negotiated result = SetFormat(pixel_format, options_.width, options_.height);
  const v4l2_fract interval = FrameInterval(options_.fps);
  SetRate(interval.numerator, interval.denominator, &result);
  return result;
}

V4l2Source::Negotiated V4l2Source::SetFormat(uint32_t pixel_format, int width, int height) {
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.width = static_cast<uint32_t>(width);
  format.fmt.pix.height = static_cast<uint32_t>(height);
  format.fmt.pix.pixelformat = pixel_format;
  format.fmt.pix.field = V4L2_FIELD_ANY;
  if (device_->Ioctl(fd_, VIDIOC_S_FMT, &format) < 0) ThrowCallError("VIDIOC_S_FMT", errno);
  v4l2_format granted{};
  granted.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (device_->Ioctl(fd_, VIDIOC_G_FMT, &granted) < 0) ThrowCallError("VIDIOC_G_FMT", errno);
  Negotiated result;
  result.pixel_format = granted.fmt.pix.pixelformat;
  result.width = static_cast<int>(granted.fmt.pix.width);
  result.height = static_cast<int>(granted.fmt.pix.height);
  result.bytes_per_line = static_cast<int>(granted.fmt.pix.bytesperline);
  if (result.width <= 0 || result.height <= 0 || result.width > 65536 || result.height > 65536)
    throw CaptureError(DeviceMessage(fmt::format("the driver chose an unusable frame size {}x{}",
                                                 granted.fmt.pix.width, granted.fmt.pix.height)));
  return result;
}

void V4l2Source::SetRate(uint32_t numerator, uint32_t denominator, Negotiated* result) {
  result->fps = 0.0;
  result->interval_numerator = numerator;
  result->interval_denominator = denominator;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe.numerator = numerator;
  parm.parm.capture.timeperframe.denominator = denominator;
  const bool rate_set = device_->Ioctl(fd_, VIDIOC_S_PARM, &parm) == 0;
  if (!rate_set && errno == ENODEV) ThrowCallError("VIDIOC_S_PARM", ENODEV);
  v4l2_fract granted{};
  if (rate_set && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) != 0) {
    granted = parm.parm.capture.timeperframe;
  } else {
    v4l2_streamparm current{};
    current.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (device_->Ioctl(fd_, VIDIOC_G_PARM, &current) == 0)
      granted = current.parm.capture.timeperframe;
  }
  result->fps = FpsOf(granted);
  if (result->fps > 0.0) {
    result->interval_numerator = granted.numerator;
    result->interval_denominator = granted.denominator;
  }
}

void V4l2Source::NegotiateFormat() {
  std::vector<uint32_t> candidates;
  switch (options_.pixel_format) {
    case V4l2PixelFormat::kYuyv:
      candidates = {V4L2_PIX_FMT_YUYV};
      break;
    case V4l2PixelFormat::kMjpeg:
      candidates = {V4L2_PIX_FMT_MJPEG};
      break;
    case V4l2PixelFormat::kAuto:
      candidates = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};
      break;
  }
  const bool automatic = options_.pixel_format == V4l2PixelFormat::kAuto;
  const auto size_matches = [this](const Negotiated& n) {
    return n.width == options_.width && n.height == options_.height;
  };
  const auto rate_matches = [this](const Negotiated& n) {
    return n.fps == 0.0 || n.fps >= options_.fps * 0.99;
  };
  // Better: the asked size first, then the higher rate; ties keep the earlier candidate.
  const auto better = [&](const Negotiated& a, const Negotiated& b) {
    if (size_matches(a) != size_matches(b)) return size_matches(a);
    return a.fps > b.fps * 1.01;
  };

  Negotiated chosen;
  Negotiated last;
  bool have = false;
  for (const uint32_t candidate : candidates) {
    last = Negotiate(candidate);
    if (!IsDecodable(last.pixel_format)) continue;
    if (!have || better(last, chosen)) chosen = last;
    have = true;
    if (automatic && last.pixel_format == V4L2_PIX_FMT_YUYV && size_matches(last) &&
        rate_matches(last))
      break;
  }
  if (!have)
    throw CaptureError(
        DeviceMessage(fmt::format("offers neither YUYV nor Motion-JPEG (the driver chose {})",
                                  FourccText(last.pixel_format))));
  if (chosen.pixel_format != last.pixel_format) chosen = Negotiate(chosen.pixel_format);

  if (!automatic && chosen.pixel_format != candidates.front())
    spdlog::warn("{}", DeviceMessage(fmt::format("asked for {}, the driver chose {}",
                                                 FourccText(candidates.front()),
                                                 FourccText(chosen.pixel_format))));
  if (!size_matches(chosen))
    spdlog::warn(
        "{}", DeviceMessage(fmt::format("asked for {}x{}, the driver chose {}x{}", options_.width,
                                        options_.height, chosen.width, chosen.height)));
  if (chosen.fps == 0.0)
    spdlog::warn(
        "{}", DeviceMessage(fmt::format(
                  "the driver does not tell its frame rate (asked for {:g} fps)", options_.fps)));
  else if (std::abs(chosen.fps - options_.fps) > options_.fps * 0.01)
    spdlog::warn("{}", DeviceMessage(fmt::format("asked for {:g} fps, the driver granted {:g} fps",
                                                 options_.fps, chosen.fps)));

  negotiated_ = chosen;
  format_.width = chosen.width;
  format_.height = chosen.height;
  format_.fps = chosen.fps;
  format_.pixel_format = FourccText(chosen.pixel_format);
}

std::optional<V4l2Source::StillTarget> V4l2Source::FindStillTarget() {
  const FrameSize video{negotiated_.width, negotiated_.height};
  std::optional<StillTarget> best;
  int64_t best_area = video.area();
  // Motion-JPEG second, so that it wins ties.
  for (const uint32_t pixel_format : {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG}) {
    for (uint32_t index = 0; index < kMaxFrameSizeEntries; ++index) {
      v4l2_frmsizeenum entry{};
      entry.index = index;
      entry.pixel_format = pixel_format;
      // EINVAL ends the list (or says the format is not offered); ENOTTY: no enumeration.
      if (device_->Ioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &entry) < 0) break;
      FrameSize size;
      if (entry.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        size = FrameSize{entry.discrete.width, entry.discrete.height};
        if (!SameAspect(size.width, size.height, video.width, video.height)) size = FrameSize{};
      } else if (entry.type == V4L2_FRMSIZE_TYPE_STEPWISE ||
                 entry.type == V4L2_FRMSIZE_TYPE_CONTINUOUS) {
        size = LargestOfAspectInRange(entry.stepwise, video);
      }
      if (size.width > 65536 || size.height > 65536) size = FrameSize{};
      if (size.area() > best_area ||
          (size.area() == best_area && best && pixel_format == V4L2_PIX_FMT_MJPEG)) {
        best =
            StillTarget{pixel_format, static_cast<int>(size.width), static_cast<int>(size.height)};
        best_area = size.area();
      }
      // A stepwise or continuous range is the only entry.
      if (entry.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;
    }
  }
  return best;
}

void V4l2Source::StartStreaming(int buffer_count) {
  v4l2_requestbuffers request{};
  request.count = static_cast<uint32_t>(buffer_count);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (device_->Ioctl(fd_, VIDIOC_REQBUFS, &request) < 0) {
    const int error = errno;
    if (error == EINVAL)
      throw CaptureError(DeviceMessage("does not support memory-mapped streaming"));
    ThrowCallError("VIDIOC_REQBUFS", error);
  }
  buffers_requested_ = true;
  if (request.count == 0) throw CaptureError(DeviceMessage("the driver granted no buffers"));
  if (request.count != static_cast<uint32_t>(buffer_count))
    spdlog::debug("{}", DeviceMessage(fmt::format("asked for {} buffers, the driver granted {}",
                                                  buffer_count, request.count)));

  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (device_->Ioctl(fd_, VIDIOC_QUERYBUF, &buffer) < 0) ThrowCallError("VIDIOC_QUERYBUF", errno);
    void* address = device_->Mmap(buffer.length, fd_, static_cast<off_t>(buffer.m.offset));
    if (address == MAP_FAILED) ThrowCallError("mmap of a capture buffer", errno);
    buffers_.push_back(Buffer{address, buffer.length});
  }
  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (device_->Ioctl(fd_, VIDIOC_QBUF, &buffer) < 0) ThrowCallError("VIDIOC_QBUF", errno);
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (device_->Ioctl(fd_, VIDIOC_STREAMON, &type) < 0) ThrowCallError("VIDIOC_STREAMON", errno);
  streaming_ = true;
}

void V4l2Source::StopStreaming() {
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    device_->Ioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (const Buffer& buffer : buffers_)
    device_->Munmap(buffer.address, buffer.length);
  buffers_.clear();
  if (buffers_requested_) {
    v4l2_requestbuffers request{};
    request.count = 0;
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    device_->Ioctl(fd_, VIDIOC_REQBUFS, &request);
    buffers_requested_ = false;
  }
}

void V4l2Source::ReleaseDevice() {
  StopStreaming();
  if (fd_ >= 0) {
    device_->Close(fd_);
    fd_ = -1;
  }
}

CaptureStatus V4l2Source::Read(CapturedFrame* frame, std::chrono::milliseconds timeout) {
  SILNET_CHECK(frame != nullptr);
  SILNET_CHECK_MSG(state_ != State::kClosed, "V4l2Source::Read() needs Open()");
  const Clock::time_point start = Clock::now();
  if (const std::optional<StillRequest> request = TakeStillRequest()) {
    std::optional<StillTarget> target;
    {
      std::lock_guard lock(mutex_);
      target = still_target_;
    }
    if (state_ != State::kStreaming) {
      AnswerStill(request->id, cv::Mat(),
                  DeviceMessage("no still: the device is away (waiting to re-open it)"));
    } else if (!target) {
      AnswerStill(request->id, cv::Mat(),
                  DeviceMessage("no still: the re-opened device offers no larger frame size"));
    } else {
      const std::string restore_error = ServeStill(*request, *target);
      if (!restore_error.empty()) return DeviceLost(frame, restore_error);
    }
  }
  const Clock::time_point deadline =
      std::max(Clock::now(), start + std::max(timeout, std::chrono::milliseconds::zero()));
  if (state_ == State::kAway && !WaitAndReopen(deadline)) return CaptureStatus::kTimeout;
  return ReadStreaming(frame, deadline);
}

bool V4l2Source::WaitAndReopen(Clock::time_point deadline) {
  const Clock::time_point next_attempt = last_reopen_attempt_ + options_.reopen_interval;
  if (Clock::now() < next_attempt) {
    if (next_attempt > deadline) {
      std::this_thread::sleep_until(deadline);
      return false;
    }
    std::this_thread::sleep_until(next_attempt);
  }
  last_reopen_attempt_ = Clock::now();
  const CaptureFormat before = format_;
  try {
    OpenDevice();
  } catch (const CaptureError& e) {
    spdlog::debug("{} (still away)", e.what());
    return false;
  }
  state_ = State::kStreaming;
  ++counters_.reopens;
  UpdateDescription();
  spdlog::info("{} is back", Describe());
  if (before.width != format_.width || before.height != format_.height ||
      before.pixel_format != format_.pixel_format || before.fps != format_.fps)
    spdlog::warn("{}", DeviceMessage(fmt::format("came back with another format ({}x{} {} {})",
                                                 format_.width, format_.height,
                                                 format_.pixel_format, FpsText(format_.fps))));
  return true;
}

CaptureStatus V4l2Source::ReadStreaming(CapturedFrame* frame, Clock::time_point deadline) {
  const int revents = device_->Poll(fd_, TimeoutMs(deadline));
  if (revents < 0) return DeviceLost(frame, fmt::format("poll failed: {}", ErrnoText(errno)));
  if (revents == 0) return CaptureStatus::kTimeout;
  if ((revents & (POLLERR | POLLHUP | POLLNVAL)) != 0)
    return DeviceLost(frame, "poll reported an error on the device");
  if ((revents & POLLIN) == 0) return CaptureStatus::kTimeout;

  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (device_->Ioctl(fd_, VIDIOC_DQBUF, &buffer) < 0) {
    const int error = errno;
    if (error == EAGAIN) return CaptureStatus::kTimeout;
    return DeviceLost(frame, fmt::format("VIDIOC_DQBUF failed: {}", ErrnoText(error)));
  }
  if (buffer.index >= buffers_.size())
    return DeviceLost(frame, fmt::format("the driver dequeued unknown buffer {}", buffer.index));

  int64_t capture_time_ns = 0;
  if ((buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) {
    const int64_t stamp_ns = static_cast<int64_t>(buffer.timestamp.tv_sec) * 1000000000LL +
                             static_cast<int64_t>(buffer.timestamp.tv_usec) * 1000LL;
    capture_time_ns = stamp_ns + (RealtimeNowNs() - MonotonicNowNs());
  } else {
    capture_time_ns = RealtimeNowNs();
  }
  const uint64_t index = IndexOf(buffer.sequence, capture_time_ns);

  cv::Mat image;
  std::string problem;
  if ((buffer.flags & V4L2_BUF_FLAG_ERROR) != 0) {
    problem = "the driver flagged the buffer as corrupt";
  } else {
    problem = Decode(buffer, negotiated_, &image);
  }

  v4l2_buffer requeue{};
  requeue.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  requeue.memory = V4L2_MEMORY_MMAP;
  requeue.index = buffer.index;
  if (device_->Ioctl(fd_, VIDIOC_QBUF, &requeue) < 0) {
    const int error = errno;
    ++counters_.dropped;
    return DeviceLost(frame, fmt::format("VIDIOC_QBUF failed: {}", ErrnoText(error)));
  }

  frame->frame_index = index;
  frame->capture_time_ns = capture_time_ns;
  if (!problem.empty()) {
    ++counters_.errors;
    ++counters_.dropped;
    last_error_ = DeviceMessage(fmt::format("frame {}: {}", index, problem));
    spdlog::debug("{}", last_error_);
    frame->image.release();
    return CaptureStatus::kFrameError;
  }
  frame->image = std::move(image);
  ++counters_.frames;
  return CaptureStatus::kFrame;
}

CaptureStatus V4l2Source::DeviceLost(CapturedFrame* frame, const std::string& reason) {
  ReleaseDevice();
  state_ = State::kAway;
  resync_ = true;
  last_reopen_attempt_ = Clock::now();
  ++counters_.errors;
  last_error_ = DeviceMessage(fmt::format("device lost ({}); trying to re-open it every {} ms",
                                          reason, options_.reopen_interval.count()));
  spdlog::warn("{}", last_error_);
  *frame = CapturedFrame{};
  return CaptureStatus::kError;
}

double V4l2Source::PeriodFps() const {
  return format_.fps > 0.0 ? format_.fps : options_.fps;
}

uint64_t V4l2Source::IndexOf(uint32_t sequence, int64_t capture_time_ns) {
  uint64_t index = 0;
  if (have_last_) {
    uint64_t step = 1;
    if (resync_) {
      const double periods =
          static_cast<double>(capture_time_ns - last_time_ns_) * PeriodFps() / 1e9;
      if (periods > 1.0) step = static_cast<uint64_t>(std::llround(periods));
    } else {
      // A repeated number (drivers that do not count) or a backward jump counts as one step.
      const uint32_t difference = sequence - last_sequence_;
      if (difference != 0 && difference < 0x80000000u) step = difference;
    }
    index = last_index_ + step;
    counters_.dropped += step - 1;
  }
  have_last_ = true;
  resync_ = false;
  last_index_ = index;
  last_sequence_ = sequence;
  last_time_ns_ = capture_time_ns;
  return index;
}

std::optional<StillPhoto> V4l2Source::TakeStill(const CapturedFrame& frame) {
  static_cast<void>(frame);
  if (!options_.full_resolution_stills) return std::nullopt;
  std::lock_guard call(still_call_mutex_);
  std::unique_lock lock(mutex_);
  if (!accepting_stills_) throw CaptureError(DeviceMessage("no still: the source is not open"));
  if (!still_target_) return std::nullopt;
  const StillRequest request{++last_still_id_, Clock::now() + options_.still_timeout};
  pending_still_ = request;
  waiting_still_id_ = request.id;
  const bool answered = still_answered_.wait_until(lock, request.deadline,
                                                   [&] { return still_answer_.id == request.id; });
  waiting_still_id_ = 0;
  if (!answered) {
    if (pending_still_ && pending_still_->id == request.id) pending_still_.reset();
    throw CaptureError(
        DeviceMessage(fmt::format("no still within {} ms", options_.still_timeout.count())));
  }
  StillAnswer answer = std::move(still_answer_);
  still_answer_ = StillAnswer{};
  if (!answer.error.empty()) throw CaptureError(answer.error);
  StillPhoto still;
  still.photo = std::move(answer.photo);
  return still;
}

bool V4l2Source::StillRequested() const {
  std::lock_guard lock(mutex_);
  return pending_still_.has_value();
}

std::optional<V4l2Source::StillRequest> V4l2Source::TakeStillRequest() {
  std::lock_guard lock(mutex_);
  std::optional<StillRequest> request = pending_still_;
  pending_still_.reset();
  return request;
}

void V4l2Source::AnswerStill(uint64_t id, cv::Mat photo, std::string error) {
  {
    std::lock_guard lock(mutex_);
    if (waiting_still_id_ != id) return;  // the caller gave up
    still_answer_ = StillAnswer{id, std::move(photo), std::move(error)};
  }
  still_answered_.notify_all();
}

std::string V4l2Source::ServeStill(const StillRequest& request, const StillTarget& target) {
  const Clock::time_point start = Clock::now();
  cv::Mat photo;
  std::string error;
  try {
    StopStreaming();
    photo = CaptureStill(target, request.deadline);
  } catch (const CaptureError& e) {
    error = e.what();
  } catch (const std::exception& e) {
    error = DeviceMessage(fmt::format("still failed: {}", e.what()));
  }
  if (error.empty()) {
    spdlog::info("{}", DeviceMessage(fmt::format("still taken at {}x{} {}", photo.cols, photo.rows,
                                                 FourccText(target.pixel_format))));
  } else {
    spdlog::warn("still not taken: {}", error);
  }
  AnswerStill(request.id, std::move(photo), std::move(error));

  // Frames are indexed by elapsed time across the switch, as after a re-open.
  resync_ = true;
  try {
    StopStreaming();
    RestoreVideo();
  } catch (const CaptureError& e) {
    return fmt::format("cannot return to the video stream after a still: {}", e.what());
  }
  spdlog::debug(
      "{}",
      DeviceMessage(fmt::format(
          "back to the video stream {} ms after the still request",
          std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count())));
  return "";
}

cv::Mat V4l2Source::CaptureStill(const StillTarget& target, Clock::time_point deadline) {
  const Negotiated still = SetFormat(target.pixel_format, target.width, target.height);
  if (!IsDecodable(still.pixel_format) ||
      int64_t{still.width} * still.height <= int64_t{negotiated_.width} * negotiated_.height ||
      !SameAspect(still.width, still.height, negotiated_.width, negotiated_.height))
    throw CaptureError(
        DeviceMessage(fmt::format("asked for {}x{} {} for the still, the driver chose {}x{} {}",
                                  target.width, target.height, FourccText(target.pixel_format),
                                  still.width, still.height, FourccText(still.pixel_format))));
  StartStreaming(kStillBuffers);

  int settle_left = options_.still_settle_frames;
  int bad_frames = 0;
  bool first = true;
  while (true) {
    // Polls that find no frame to dequeue repeat only until the deadline.
    if (!first && Clock::now() >= deadline)
      throw CaptureError(DeviceMessage("no frame at the still size in time"));
    first = false;
    const int revents = device_->Poll(fd_, TimeoutMs(deadline));
    if (revents < 0) ThrowCallError("poll", errno);
    if (revents == 0) throw CaptureError(DeviceMessage("no frame at the still size in time"));
    if ((revents & (POLLERR | POLLHUP | POLLNVAL)) != 0)
      throw CaptureError(DeviceMessage("poll reported an error on the device"));
    if ((revents & POLLIN) == 0) continue;

    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (device_->Ioctl(fd_, VIDIOC_DQBUF, &buffer) < 0) {
      const int error = errno;
      if (error == EAGAIN) continue;
      ThrowCallError("VIDIOC_DQBUF", error);
    }
    if (buffer.index >= buffers_.size())
      throw CaptureError(
          DeviceMessage(fmt::format("the driver dequeued unknown buffer {}", buffer.index)));
    cv::Mat image;
    std::string problem;
    if (settle_left == 0) {
      problem = (buffer.flags & V4L2_BUF_FLAG_ERROR) != 0
                    ? std::string("the driver flagged the buffer as corrupt")
                    : Decode(buffer, still, &image);
    }
    v4l2_buffer requeue{};
    requeue.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    requeue.memory = V4L2_MEMORY_MMAP;
    requeue.index = buffer.index;
    if (device_->Ioctl(fd_, VIDIOC_QBUF, &requeue) < 0) ThrowCallError("VIDIOC_QBUF", errno);

    if (settle_left > 0) {
      --settle_left;
      continue;
    }
    if (problem.empty()) return image;
    if (++bad_frames > kMaxBadStillFrames)
      throw CaptureError(DeviceMessage(
          fmt::format("{} bad frames at the still size; the last: {}", bad_frames, problem)));
    spdlog::debug("{}", DeviceMessage(fmt::format("bad still frame skipped: {}", problem)));
  }
}

void V4l2Source::RestoreVideo() {
  Negotiated restored = SetFormat(negotiated_.pixel_format, negotiated_.width, negotiated_.height);
  SetRate(negotiated_.interval_numerator, negotiated_.interval_denominator, &restored);
  const bool same_rate = std::abs(restored.fps - negotiated_.fps) <= 1e-6 * negotiated_.fps;
  if (restored.pixel_format != negotiated_.pixel_format || restored.width != negotiated_.width ||
      restored.height != negotiated_.height ||
      restored.bytes_per_line != negotiated_.bytes_per_line || !same_rate)
    throw CaptureError(DeviceMessage(
        fmt::format("the driver granted {}x{} {} {} instead of the video format {}x{} {} {}",
                    restored.width, restored.height, FourccText(restored.pixel_format),
                    FpsText(restored.fps), negotiated_.width, negotiated_.height,
                    FourccText(negotiated_.pixel_format), FpsText(negotiated_.fps))));
  StartStreaming(options_.buffer_count);
}

std::string V4l2Source::Decode(const v4l2_buffer& buffer, const Negotiated& format,
                               cv::Mat* image) const {
  const Buffer& mapped = buffers_[buffer.index];
  auto* data = static_cast<uint8_t*>(mapped.address);
  const size_t used = buffer.bytesused;
  if (used > mapped.length)
    return fmt::format("the driver reports {} bytes in a buffer of {}", used, mapped.length);
  const int width = format.width;
  const int height = format.height;

  if (format.pixel_format == V4L2_PIX_FMT_YUYV) {
    const size_t stride = std::max<size_t>(static_cast<size_t>(format.bytes_per_line),
                                           static_cast<size_t>(width) * 2);
    const size_t needed = stride * static_cast<size_t>(height - 1) + static_cast<size_t>(width) * 2;
    if (used < needed) return fmt::format("short frame ({} of {} bytes)", used, needed);
    const cv::Mat yuyv(height, width, CV_8UC2, data, stride);
    cv::cvtColor(yuyv, *image, cv::COLOR_YUV2BGR_YUYV);
    return "";
  }

  if (!JpegLooksComplete(data, used))
    return "corrupt Motion-JPEG frame (JPEG start or end marker missing)";
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(cv::Mat(1, static_cast<int>(used), CV_8UC1, data), cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    return fmt::format("corrupt Motion-JPEG frame ({})", e.what());
  }
  if (decoded.empty()) return "corrupt Motion-JPEG frame (cannot be decoded)";
  if (decoded.cols != width || decoded.rows != height)
    return fmt::format("wrong-size frame: {}x{} instead of {}x{}", decoded.cols, decoded.rows,
                       width, height);
  *image = std::move(decoded);
  return "";
}

}  // namespace silnet::node
