#include "tests/node/v4l2/fake_v4l2_device.h"

#include <fmt/format.h>
#include <poll.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <utility>

namespace silnet::node {
namespace {

// Forwards every call to a shared fake.
class FakeHandle : public V4l2Device {
 public:
  explicit FakeHandle(std::shared_ptr<FakeV4l2Device> fake) : fake_(std::move(fake)) {}
  int Open(const std::string& path, int flags) override { return fake_->Open(path, flags); }
  int Close(int fd) override { return fake_->Close(fd); }
  int Ioctl(int fd, unsigned long request, void* arg) override {
    return fake_->Ioctl(fd, request, arg);
  }
  void* Mmap(size_t length, int fd, off_t offset) override {
    return fake_->Mmap(length, fd, offset);
  }
  int Munmap(void* address, size_t length) override { return fake_->Munmap(address, length); }
  int Poll(int fd, int timeout_ms) override { return fake_->Poll(fd, timeout_ms); }

 private:
  std::shared_ptr<FakeV4l2Device> fake_;
};

}  // namespace

cv::Mat FakeBgrPattern(int width, int height, uint64_t tick) {
  cv::Mat image(height, width, CV_8UC3);
  const auto red = static_cast<uint8_t>((37 * tick) % 256);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<uint8_t>(x * 255 / std::max(1, width - 1)),
                    static_cast<uint8_t>(y * 255 / std::max(1, height - 1)), red);
    }
  }
  return image;
}

FakeYuv FakeYuyvPixel(int x, int y, uint64_t tick) {
  const auto t = static_cast<int>(tick % 10000);
  const int pair = x / 2;
  return FakeYuv{16 + (3 * x + 2 * y + 5 * t) % 220, 48 + (5 * pair + y + 3 * t) % 160,
                 48 + (3 * pair + 2 * y + 7 * t) % 160};
}

FakeV4l2Device::FakeV4l2Device(FakeV4l2Config config) : config_(std::move(config)) {
  for (const auto& [pixel_format, sizes] : config_.frame_sizes) {
    for (const FakeFrameSizes& entry : sizes) {
      if (entry.type != V4L2_FRMSIZE_TYPE_DISCRETE && sizes.size() != 1)
        throw std::invalid_argument("a stepwise or continuous frame-size range must be alone");
    }
  }
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  monotonic_base_ns_ = static_cast<int64_t>(now.tv_sec) * 1000000000LL + now.tv_nsec;
  ResetDriver();
}

FakeV4l2Device::~FakeV4l2Device() = default;

std::unique_ptr<V4l2Device> FakeV4l2Device::Handle(std::shared_ptr<FakeV4l2Device> fake) {
  return std::make_unique<FakeHandle>(std::move(fake));
}

int FakeV4l2Device::Fail(int error) {
  errno = error;
  return -1;
}

int FakeV4l2Device::Violation(const std::string& what, int error) {
  violations_.push_back(what);
  return Fail(error);
}

size_t FakeV4l2Device::mappings() const {
  size_t count = 0;
  for (const auto& [address, mapping] : mappings_)
    count += static_cast<size_t>(mapping.count);
  return count;
}

bool FakeV4l2Device::AnyBufferMapped() const {
  for (const Buffer& buffer : buffers_) {
    for (const auto& [address, mapping] : mappings_) {
      if (mapping.memory == buffer.memory) return true;
    }
  }
  return false;
}

double FakeV4l2Device::HighestFps(uint32_t pixel_format) const {
  const auto found = config_.max_fps.find(pixel_format);
  return found != config_.max_fps.end() ? found->second : 60.0;
}

void FakeV4l2Device::ResetDriver() {
  buffers_.clear();
  queued_.clear();
  done_.clear();
  owner_fd_ = -1;
  streaming_ = false;
  fps_ = std::min(config_.default_fps, HighestFps(config_.pixel_formats.front()));
  v4l2_format format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  format.fmt.pix.width = 640;
  format.fmt.pix.height = 480;
  format.fmt.pix.pixelformat = config_.pixel_formats.front();
  SetFormat(&format, /*refusable=*/false);
}

int FakeV4l2Device::Open(const std::string& path, int flags) {
  static_cast<void>(flags);
  ++open_attempts_;
  if (config_.open_errno != 0) return Fail(config_.open_errno);
  if (path != config_.path) return Fail(ENOENT);
  if (gone_) {
    if (reopen_failures_left_ > 0) {
      --reopen_failures_left_;
      return Fail(ENOENT);
    }
    gone_ = false;
  }
  const int fd = next_fd_++;
  descriptors_[fd] = false;
  return fd;
}

int FakeV4l2Device::Close(int fd) {
  const auto found = descriptors_.find(fd);
  if (found == descriptors_.end())
    return Violation(fmt::format("close of unknown fd {}", fd), EBADF);
  const bool stale = found->second;
  descriptors_.erase(found);
  // Closing the streaming descriptor releases the queue, as vb2 does.
  if (!stale && fd == owner_fd_) {
    streaming_ = false;
    buffers_.clear();
    queued_.clear();
    done_.clear();
    owner_fd_ = -1;
  }
  return 0;
}

int FakeV4l2Device::Ioctl(int fd, unsigned long request, void* arg) {
  const auto found = descriptors_.find(fd);
  if (found == descriptors_.end())
    return Violation(fmt::format("ioctl {:#x} on unknown fd {}", request, fd), EBADF);
  if (found->second) return Fail(ENODEV);
  if (arg == nullptr)
    return Violation(fmt::format("ioctl {:#x} without argument", request), EFAULT);
  switch (request) {
    case VIDIOC_QUERYCAP:
      return QueryCap(static_cast<v4l2_capability*>(arg));
    case VIDIOC_S_FMT:
      // vb2: the format cannot change while the queue has buffers (streaming or not).
      if (streaming_) return Violation("VIDIOC_S_FMT while streaming", EBUSY);
      if (!buffers_.empty()) return Violation("VIDIOC_S_FMT while buffers are allocated", EBUSY);
      return SetFormat(static_cast<v4l2_format*>(arg));
    case VIDIOC_G_FMT:
      return GetFormat(static_cast<v4l2_format*>(arg));
    case VIDIOC_S_PARM:
      return SetParm(static_cast<v4l2_streamparm*>(arg));
    case VIDIOC_G_PARM:
      return GetParm(static_cast<v4l2_streamparm*>(arg));
    case VIDIOC_ENUM_FRAMESIZES:
      return EnumFrameSizes(static_cast<v4l2_frmsizeenum*>(arg));
    case VIDIOC_REQBUFS:
      return RequestBuffers(fd, static_cast<v4l2_requestbuffers*>(arg));
    case VIDIOC_QUERYBUF:
      return QueryBuffer(static_cast<v4l2_buffer*>(arg));
    case VIDIOC_QBUF:
      return QueueBuffer(fd, static_cast<v4l2_buffer*>(arg));
    case VIDIOC_DQBUF:
      return DequeueBuffer(static_cast<v4l2_buffer*>(arg));
    case VIDIOC_STREAMON:
      return StreamOn(static_cast<const int*>(arg));
    case VIDIOC_STREAMOFF:
      return StreamOff(static_cast<const int*>(arg));
    default:
      return Fail(ENOTTY);
  }
}

int FakeV4l2Device::QueryCap(v4l2_capability* capability) {
  *capability = v4l2_capability{};
  std::strncpy(reinterpret_cast<char*>(capability->driver), "fake", sizeof(capability->driver));
  std::strncpy(reinterpret_cast<char*>(capability->card), "Fake Camera", sizeof(capability->card));
  std::strncpy(reinterpret_cast<char*>(capability->bus_info), "platform:fake",
               sizeof(capability->bus_info));
  capability->version = 0x060100;
  capability->device_caps = config_.capabilities;
  capability->capabilities = config_.capabilities | V4L2_CAP_DEVICE_CAPS;
  return 0;
}

int FakeV4l2Device::SetFormat(v4l2_format* format, bool refusable) {
  if (format->type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_S_FMT with a buffer type other than video capture", EINVAL);
  v4l2_pix_format& pix = format->fmt.pix;
  const auto& formats = config_.pixel_formats;
  if (std::find(formats.begin(), formats.end(), pix.pixelformat) == formats.end())
    pix.pixelformat = formats.front();
  const cv::Size granted = GrantedSize(
      pix.pixelformat, cv::Size(static_cast<int>(std::min<uint32_t>(pix.width, 1 << 20)),
                                static_cast<int>(std::min<uint32_t>(pix.height, 1 << 20))));
  if (refusable && std::find(config_.refused_sizes.begin(), config_.refused_sizes.end(), granted) !=
                       config_.refused_sizes.end())
    return Fail(EIO);
  const int width = granted.width;
  const int height = granted.height;
  pix.width = static_cast<uint32_t>(width);
  pix.height = static_cast<uint32_t>(height);
  pix.field = V4L2_FIELD_NONE;
  pix.colorspace = V4L2_COLORSPACE_SRGB;
  if (pix.pixelformat == V4L2_PIX_FMT_YUYV) {
    pix.bytesperline = static_cast<uint32_t>(width * 2 + config_.line_padding);
    pix.sizeimage = pix.bytesperline * pix.height;
  } else {
    pix.bytesperline = 0;
    pix.sizeimage = static_cast<uint32_t>(width * height * 2 + 4096);
  }
  format_ = pix;
  fps_ = std::min(fps_ > 0.0 ? fps_ : config_.default_fps, HighestFps(pix.pixelformat));
  return 0;
}

cv::Size FakeV4l2Device::GrantedSize(uint32_t pixel_format, cv::Size asked) const {
  if (config_.forced_size) return {config_.forced_size->width & ~1, config_.forced_size->height};
  const auto listed = config_.frame_sizes.find(pixel_format);
  if (listed == config_.frame_sizes.end() || listed->second.empty()) {
    return {std::clamp(asked.width, 16, config_.max_width) & ~1,
            std::clamp(asked.height, 16, config_.max_height)};
  }
  const std::vector<FakeFrameSizes>& sizes = listed->second;
  if (sizes.front().type != V4L2_FRMSIZE_TYPE_DISCRETE) {
    const FakeFrameSizes& range = sizes.front();
    const auto nearest = [](int value, int min, int max, int step) {
      const int clamped = std::clamp(value, min, max);
      const int k = static_cast<int>(std::lround(static_cast<double>(clamped - min) / step));
      return std::min(min + k * step, min + (max - min) / step * step);
    };
    return {nearest(asked.width, range.min.width, range.max.width, range.step.width),
            nearest(asked.height, range.min.height, range.max.height, range.step.height)};
  }
  // uvcvideo's choice: the least area outside the intersection of asked and offered.
  cv::Size best;
  int64_t best_distance = INT64_MAX;
  for (const FakeFrameSizes& entry : sizes) {
    const int64_t w = entry.min.width, h = entry.min.height;
    const int64_t common = std::min<int64_t>(w, asked.width) * std::min<int64_t>(h, asked.height);
    const int64_t distance = w * h + int64_t{asked.width} * asked.height - 2 * common;
    if (distance < best_distance) {
      best_distance = distance;
      best = entry.min;
    }
  }
  return best;
}

int FakeV4l2Device::EnumFrameSizes(v4l2_frmsizeenum* entry) {
  if (config_.frame_sizes.empty()) return Fail(ENOTTY);
  const auto& formats = config_.pixel_formats;
  const auto listed = config_.frame_sizes.find(entry->pixel_format);
  if (std::find(formats.begin(), formats.end(), entry->pixel_format) == formats.end() ||
      listed == config_.frame_sizes.end() || entry->index >= listed->second.size())
    return Fail(EINVAL);
  const FakeFrameSizes& sizes = listed->second[entry->index];
  entry->type = sizes.type;
  if (sizes.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
    entry->discrete.width = static_cast<uint32_t>(sizes.min.width);
    entry->discrete.height = static_cast<uint32_t>(sizes.min.height);
  } else {
    entry->stepwise.min_width = static_cast<uint32_t>(sizes.min.width);
    entry->stepwise.max_width = static_cast<uint32_t>(sizes.max.width);
    entry->stepwise.step_width = static_cast<uint32_t>(sizes.step.width);
    entry->stepwise.min_height = static_cast<uint32_t>(sizes.min.height);
    entry->stepwise.max_height = static_cast<uint32_t>(sizes.max.height);
    entry->stepwise.step_height = static_cast<uint32_t>(sizes.step.height);
  }
  return 0;
}

int FakeV4l2Device::GetFormat(v4l2_format* format) {
  if (format->type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_G_FMT with a buffer type other than video capture", EINVAL);
  format->fmt.pix = format_;
  return 0;
}

int FakeV4l2Device::SetParm(v4l2_streamparm* parm) {
  if (!config_.supports_frame_rate) return Fail(ENOTTY);
  if (parm->type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_S_PARM with a buffer type other than video capture", EINVAL);
  if (streaming_) return Violation("VIDIOC_S_PARM while streaming", EBUSY);
  const v4l2_fract asked = parm->parm.capture.timeperframe;
  double fps = config_.default_fps;
  if (asked.numerator != 0 && asked.denominator != 0)
    fps = static_cast<double>(asked.denominator) / asked.numerator;
  fps_ = std::min(fps, HighestFps(format_.pixelformat));
  return GetParm(parm);
}

int FakeV4l2Device::GetParm(v4l2_streamparm* parm) {
  if (!config_.supports_frame_rate) return Fail(ENOTTY);
  if (parm->type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_G_PARM with a buffer type other than video capture", EINVAL);
  parm->parm.capture = v4l2_captureparm{};
  parm->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
  parm->parm.capture.timeperframe.numerator = 1000;
  parm->parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(fps_ * 1000.0));
  return 0;
}

int FakeV4l2Device::RequestBuffers(int fd, v4l2_requestbuffers* request) {
  if (request->type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_REQBUFS with a buffer type other than video capture", EINVAL);
  if (request->memory != V4L2_MEMORY_MMAP)
    return Violation("VIDIOC_REQBUFS with memory other than MMAP", EINVAL);
  if (owner_fd_ >= 0 && owner_fd_ != fd)
    return Violation("VIDIOC_REQBUFS from a descriptor that does not own the queue", EBUSY);
  if (streaming_) return Violation("VIDIOC_REQBUFS while streaming", EBUSY);
  if (AnyBufferMapped()) return Violation("VIDIOC_REQBUFS while buffers are still mapped", EBUSY);
  buffers_.clear();
  queued_.clear();
  done_.clear();
  owner_fd_ = -1;
  if (request->count == 0) return 0;
  const uint32_t count = std::min(request->count, config_.max_buffers);
  offset_base_ += 0x1000000;  // offsets of a new allocation never match older ones
  for (uint32_t i = 0; i < count; ++i) {
    Buffer buffer;
    buffer.memory = std::make_shared<std::vector<uint8_t>>(format_.sizeimage, 0);
    buffer.offset = offset_base_ + i * 0x100000;
    buffers_.push_back(std::move(buffer));
  }
  request->count = count;
  owner_fd_ = fd;
  return 0;
}

int FakeV4l2Device::QueryBuffer(v4l2_buffer* buffer) {
  if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_QUERYBUF with a buffer type other than video capture", EINVAL);
  if (buffer->index >= buffers_.size())
    return Violation(fmt::format("VIDIOC_QUERYBUF of unknown buffer {}", buffer->index), EINVAL);
  const Buffer& b = buffers_[buffer->index];
  buffer->memory = V4L2_MEMORY_MMAP;
  buffer->m.offset = b.offset;
  buffer->length = static_cast<uint32_t>(b.memory->size());
  buffer->bytesused = b.bytesused;
  buffer->flags = (b.state == BufferState::kQueued ? V4L2_BUF_FLAG_QUEUED : 0u) |
                  (b.state == BufferState::kDone ? V4L2_BUF_FLAG_DONE : 0u);
  return 0;
}

int FakeV4l2Device::QueueBuffer(int fd, v4l2_buffer* buffer) {
  if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || buffer->memory != V4L2_MEMORY_MMAP)
    return Violation("VIDIOC_QBUF with the wrong buffer type or memory", EINVAL);
  if (fd != owner_fd_)
    return Violation("VIDIOC_QBUF from a descriptor that does not own the queue", EBUSY);
  if (buffer->index >= buffers_.size())
    return Violation(fmt::format("VIDIOC_QBUF of unknown buffer {}", buffer->index), EINVAL);
  Buffer& b = buffers_[buffer->index];
  if (b.state != BufferState::kWithCaller)
    return Violation(fmt::format("VIDIOC_QBUF of buffer {} that is not dequeued", buffer->index),
                     EINVAL);
  b.state = BufferState::kQueued;
  queued_.push_back(buffer->index);
  return 0;
}

int FakeV4l2Device::DequeueBuffer(v4l2_buffer* buffer) {
  if (buffer->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || buffer->memory != V4L2_MEMORY_MMAP)
    return Violation("VIDIOC_DQBUF with the wrong buffer type or memory", EINVAL);
  if (!streaming_) return Violation("VIDIOC_DQBUF before VIDIOC_STREAMON", EINVAL);
  if (pending_loss_errno_ != 0) {
    const int error = pending_loss_errno_;
    pending_loss_errno_ = 0;
    gone_ = true;
    for (auto& [fd, stale] : descriptors_)
      stale = true;
    ResetDriver();
    return Fail(error);
  }
  if (done_.empty()) return Fail(EAGAIN);
  const uint32_t index = done_.front();
  done_.pop_front();
  Buffer& b = buffers_[index];
  b.state = BufferState::kWithCaller;
  const int64_t period_ns = std::llround(1e9 / fps_);
  const int64_t stamp_ns = monotonic_base_ns_ + static_cast<int64_t>(b.tick) * period_ns;
  *buffer = v4l2_buffer{};
  buffer->index = index;
  buffer->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer->memory = V4L2_MEMORY_MMAP;
  buffer->bytesused = b.bytesused;
  buffer->flags = b.flags | (config_.monotonic_timestamps ? V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC
                                                          : V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN);
  buffer->field = V4L2_FIELD_NONE;
  buffer->timestamp.tv_sec = static_cast<time_t>(stamp_ns / 1000000000LL);
  buffer->timestamp.tv_usec = static_cast<suseconds_t>((stamp_ns % 1000000000LL) / 1000);
  buffer->sequence = b.sequence;
  buffer->m.offset = b.offset;
  buffer->length = static_cast<uint32_t>(b.memory->size());
  deliveries_.push_back(
      FakeV4l2Delivery{b.tick, b.sequence, b.bytesused, index, b.kind, b.size, b.pixel_format});
  return 0;
}

int FakeV4l2Device::StreamOn(const int* type) {
  if (*type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_STREAMON with a buffer type other than video capture", EINVAL);
  if (buffers_.empty()) return Violation("VIDIOC_STREAMON without buffers", EINVAL);
  ++streamon_calls_;
  streaming_ = true;
  sequence_ = config_.first_sequence;
  tick_ += config_.streamon_periods;
  return 0;
}

int FakeV4l2Device::StreamOff(const int* type) {
  if (*type != V4L2_BUF_TYPE_VIDEO_CAPTURE)
    return Violation("VIDIOC_STREAMOFF with a buffer type other than video capture", EINVAL);
  ++streamoff_calls_;
  streaming_ = false;
  for (Buffer& b : buffers_)
    b.state = BufferState::kWithCaller;
  queued_.clear();
  done_.clear();
  return 0;
}

void* FakeV4l2Device::Mmap(size_t length, int fd, off_t offset) {
  const auto found = descriptors_.find(fd);
  if (found == descriptors_.end()) {
    Violation(fmt::format("mmap on unknown fd {}", fd), EBADF);
    return MAP_FAILED;
  }
  if (found->second) {
    Fail(ENODEV);
    return MAP_FAILED;
  }
  for (Buffer& b : buffers_) {
    if (static_cast<off_t>(b.offset) != offset) continue;
    if (length != b.memory->size()) {
      Violation(fmt::format("mmap of {} bytes of a {}-byte buffer", length, b.memory->size()),
                EINVAL);
      return MAP_FAILED;
    }
    void* address = b.memory->data();
    Mapping& mapping = mappings_[address];
    mapping.memory = b.memory;
    mapping.length = length;
    ++mapping.count;
    return address;
  }
  Violation(fmt::format("mmap of unknown offset {:#x}", offset), EINVAL);
  return MAP_FAILED;
}

int FakeV4l2Device::Munmap(void* address, size_t length) {
  const auto found = mappings_.find(address);
  if (found == mappings_.end()) return Violation("munmap of an address that is not mapped", EINVAL);
  if (found->second.length != length)
    return Violation(
        fmt::format("munmap of {} bytes of a {}-byte mapping", length, found->second.length),
        EINVAL);
  if (--found->second.count == 0) mappings_.erase(found);
  return 0;
}

int FakeV4l2Device::Poll(int fd, int timeout_ms) {
  static_cast<void>(timeout_ms);
  const auto found = descriptors_.find(fd);
  if (found == descriptors_.end()) {
    violations_.push_back(fmt::format("poll on unknown fd {}", fd));
    return POLLNVAL;
  }
  if (found->second) return POLLERR;
  if (!streaming_) {
    violations_.push_back("poll before VIDIOC_STREAMON");
    return POLLERR;
  }
  if (pending_loss_errno_ != 0 || !done_.empty()) return POLLIN | POLLRDNORM;
  FakeV4l2Step step = FakeV4l2Step::Frame();
  if (next_step_ < config_.script.size()) {
    step = config_.script[next_step_++];
  } else if (!config_.frames_after_script) {
    return 0;
  }
  switch (step.kind) {
    case FakeV4l2Step::Kind::kNoFrame:
      return 0;
    case FakeV4l2Step::Kind::kDisappear:
      Unplug(step);
      return step.loss_errno == 0 ? POLLERR : POLLIN | POLLRDNORM;
    default:
      break;
  }
  sequence_ += step.skip;
  tick_ += step.skip;
  if (queued_.empty()) {
    ++starved_frames_;
    violations_.push_back(fmt::format("frame {} arrived with no buffer queued", tick_));
    ++sequence_;
    ++tick_;
    return POLLERR;
  }
  Produce(step);
  ++sequence_;
  ++tick_;
  return POLLIN | POLLRDNORM;
}

void FakeV4l2Device::Unplug(const FakeV4l2Step& step) {
  reopen_failures_left_ = step.failed_reopens;
  tick_ += step.away_periods;
  if (step.loss_errno != 0) {
    // The driver notices on the next DQBUF.
    pending_loss_errno_ = step.loss_errno;
    return;
  }
  gone_ = true;
  for (auto& [fd, stale] : descriptors_)
    stale = true;
  ResetDriver();
}

void FakeV4l2Device::Produce(const FakeV4l2Step& step) {
  const uint32_t index = queued_.front();
  queued_.pop_front();
  Buffer& b = buffers_[index];
  std::vector<uint8_t>& memory = *b.memory;
  std::fill(memory.begin(), memory.end(), uint8_t{0xA5});
  const int width = static_cast<int>(format_.width);
  const int height = static_cast<int>(format_.height);
  uint32_t bytesused = 0;
  if (format_.pixelformat == V4L2_PIX_FMT_YUYV) {
    for (int y = 0; y < height; ++y) {
      uint8_t* row = memory.data() + static_cast<size_t>(y) * format_.bytesperline;
      for (int x = 0; x < width; x += 2) {
        const FakeYuv left = FakeYuyvPixel(x, y, tick_);
        const FakeYuv right = FakeYuyvPixel(x + 1, y, tick_);
        row[2 * x] = static_cast<uint8_t>(left.y);
        row[2 * x + 1] = static_cast<uint8_t>(left.u);
        row[2 * x + 2] = static_cast<uint8_t>(right.y);
        row[2 * x + 3] = static_cast<uint8_t>(left.v);
      }
    }
    bytesused = format_.sizeimage;
    if (step.kind == FakeV4l2Step::Kind::kCorruptJpeg ||
        step.kind == FakeV4l2Step::Kind::kTruncatedJpeg)
      bytesused /= 2;
  } else if (format_.pixelformat == V4L2_PIX_FMT_MJPEG ||
             format_.pixelformat == V4L2_PIX_FMT_JPEG) {
    std::vector<uint8_t> jpeg;
    if (step.kind == FakeV4l2Step::Kind::kCorruptJpeg) {
      jpeg.resize(1500);
      for (size_t i = 0; i < jpeg.size(); ++i)
        jpeg[i] = static_cast<uint8_t>((i * 131 + 7) % 251);
    } else {
      cv::imencode(".jpg", FakeBgrPattern(width, height, tick_), jpeg,
                   {cv::IMWRITE_JPEG_QUALITY, config_.jpeg_quality});
      if (step.kind == FakeV4l2Step::Kind::kTruncatedJpeg) {
        jpeg.resize(jpeg.size() / 2);
      } else {
        jpeg.resize(jpeg.size() + (tick_ % 4) * 100, 0);
      }
    }
    if (jpeg.size() > memory.size()) throw std::logic_error("fake JPEG larger than its buffer");
    std::copy(jpeg.begin(), jpeg.end(), memory.begin());
    bytesused = static_cast<uint32_t>(jpeg.size());
  } else {
    bytesused = format_.sizeimage;
  }
  b.bytesused = bytesused;
  b.flags = step.kind == FakeV4l2Step::Kind::kErrorFrame ? V4L2_BUF_FLAG_ERROR : 0u;
  b.sequence = sequence_;
  b.tick = tick_;
  b.kind = step.kind;
  b.size = cv::Size(width, height);
  b.pixel_format = format_.pixelformat;
  b.state = BufferState::kDone;
  done_.push_back(index);
}

}  // namespace silnet::node
