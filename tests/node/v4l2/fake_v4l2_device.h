#pragma once
// A scripted stand-in for a V4L2 camera driver, for testing V4l2Source without cameras. It
// answers the ioctls of memory-mapped capture like a driver does (granting its own size, rate
// and buffer count when it must), keeps real memory behind the mapped buffers, produces the
// frames of a script (YUYV or Motion-JPEG payloads at the size set now, sequence gaps,
// error-flagged buffers, corrupt JPEG, an unplugged device coming back), enumerates the frame
// sizes of a camera, and records every violation of the V4L2 protocol by its caller.

#include <linux/videodev2.h>

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "node/capture/v4l2/v4l2_device.h"

namespace silnet::node {

// One thing the fake camera does when the caller waits for a frame.
struct FakeV4l2Step {
  enum class Kind {
    kFrame,          // a good frame in the granted format
    kErrorFrame,     // a frame the driver flags with V4L2_BUF_FLAG_ERROR
    kCorruptJpeg,    // bytes that are no JPEG at all (YUYV: a short frame)
    kTruncatedJpeg,  // a good JPEG cut in half (YUYV: a short frame)
    kNoFrame,        // nothing arrives: this poll times out
    kDisappear,      // the device is unplugged
  };

  // A good frame after `skip` frames the sensor lost (the sequence number jumps by skip + 1).
  static FakeV4l2Step Frame(uint32_t skip = 0) { return {Kind::kFrame, skip}; }
  // A frame of `kind` (kErrorFrame, kCorruptJpeg, kTruncatedJpeg).
  static FakeV4l2Step Bad(Kind kind) { return {kind, 0}; }
  // A poll that times out.
  static FakeV4l2Step NoFrame() { return {Kind::kNoFrame, 0}; }
  // The device is unplugged: poll reports POLLERR (`loss_errno` 0) or DQBUF fails with
  // `loss_errno` (ENODEV, EIO); then `failed_reopens` open attempts fail with ENOENT, and
  // `away_periods` frame periods pass before the next frame of the re-opened device.
  static FakeV4l2Step Disappear(int loss_errno, int failed_reopens, uint64_t away_periods) {
    return {Kind::kDisappear, 0, loss_errno, failed_reopens, away_periods};
  }

  Kind kind = Kind::kFrame;
  uint32_t skip = 0;
  int loss_errno = 0;
  int failed_reopens = 0;
  uint64_t away_periods = 0;
};

// One VIDIOC_ENUM_FRAMESIZES entry: a discrete size, or a range min + k * step per axis.
struct FakeFrameSizes {
  static FakeFrameSizes Discrete(int width, int height) {
    return {V4L2_FRMSIZE_TYPE_DISCRETE, {width, height}, {width, height}, {1, 1}};
  }
  static FakeFrameSizes Stepwise(cv::Size min, cv::Size max, cv::Size step) {
    return {V4L2_FRMSIZE_TYPE_STEPWISE, min, max, step};
  }
  // Every size from min to max (step 1).
  static FakeFrameSizes Continuous(cv::Size min, cv::Size max) {
    return {V4L2_FRMSIZE_TYPE_CONTINUOUS, min, max, {1, 1}};
  }

  uint32_t type = V4L2_FRMSIZE_TYPE_DISCRETE;
  cv::Size min;
  cv::Size max;
  cv::Size step{1, 1};
};

// The simulated device and its driver.
struct FakeV4l2Config {
  std::string path = "/dev/video0";
  // Every open() fails with this errno when non-zero.
  int open_errno = 0;
  // VIDIOC_QUERYCAP device capabilities.
  uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  // Pixel formats the driver supports; it falls back to the first for any other.
  std::vector<uint32_t> pixel_formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};
  // Largest frame size; larger requests are clamped (without frame_sizes).
  int max_width = 1920;
  int max_height = 1080;
  // The frame sizes VIDIOC_ENUM_FRAMESIZES lists per pixel format (a stepwise or continuous
  // range must be the only entry); S_FMT grants the listed size nearest to the asked one (as
  // uvcvideo does) or the range's nearest step. Empty: the driver does not enumerate sizes
  // (ENOTTY) and S_FMT clamps to max_width x max_height; a format without a list: EINVAL.
  std::map<uint32_t, std::vector<FakeFrameSizes>> frame_sizes;
  // VIDIOC_S_FMT fails with EIO when it would grant one of these sizes (a mode the camera
  // refuses); the format stays as it was.
  std::vector<cv::Size> refused_sizes;
  // Frame periods that pass at each VIDIOC_STREAMON before the first frame (sensor start).
  uint64_t streamon_periods = 0;
  // When set, the driver grants this size whatever is asked.
  std::optional<cv::Size> forced_size;
  // Extra bytes at the end of every YUYV line (bytesperline = 2 * width + padding).
  int line_padding = 0;
  // Whether VIDIOC_S_PARM/G_PARM set and report the frame interval.
  bool supports_frame_rate = true;
  // Highest rate per pixel format (absent: 60); the driver grants min(asked, highest).
  std::map<uint32_t, double> max_fps;
  // The rate before any S_PARM (and always, without frame-rate support).
  double default_fps = 30.0;
  // Most buffers VIDIOC_REQBUFS grants.
  uint32_t max_buffers = 8;
  // Timestamps on CLOCK_MONOTONIC (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) or unknown.
  bool monotonic_timestamps = true;
  // Sequence number of the first frame after each VIDIOC_STREAMON.
  uint32_t first_sequence = 0;
  // Quality of the Motion-JPEG frames. Good frames are followed by (tick mod 4) * 100 zero
  // bytes inside bytesused, as some cameras pad them, so bytesused varies from frame to frame.
  int jpeg_quality = 90;
  // What happens, one step per frame; after the last step every poll times out, or finds a
  // good frame when frames_after_script.
  std::vector<FakeV4l2Step> script;
  bool frames_after_script = false;
};

// One buffer the caller dequeued.
struct FakeV4l2Delivery {
  uint64_t tick = 0;  // frame periods since the fake was made; the payload shows this tick
  uint32_t sequence = 0;
  uint32_t bytesused = 0;
  uint32_t buffer = 0;
  FakeV4l2Step::Kind kind = FakeV4l2Step::Kind::kFrame;
  cv::Size size;              // the frame size it was produced at
  uint32_t pixel_format = 0;  // and the pixel format
};

// The colour test pattern of the Motion-JPEG frame at `tick` (CV_8UC3 BGR): blue grows to the
// right, green downwards, red is (37 * tick) mod 256.
cv::Mat FakeBgrPattern(int width, int height, uint64_t tick);

// One YUV sample; all values are within the video range 16..240.
struct FakeYuv {
  int y = 0;
  int u = 0;
  int v = 0;
};
// The sample of pixel (x, y) in the YUYV frame at `tick`: its own luma and the chroma its pair
// of pixels shares.
FakeYuv FakeYuyvPixel(int x, int y, uint64_t tick);

// The scripted driver. Poll never waits: a frame is ready at once or the poll times out.
class FakeV4l2Device : public V4l2Device {
 public:
  // A device that follows `config`; the monotonic clock of its timestamps starts at the
  // current CLOCK_MONOTONIC instant (tick 0); a frame's timestamp is tick 0 plus its tick
  // times the frame period of the rate set when it is dequeued. Throws std::invalid_argument
  // for a frame-size list that mixes a range with other entries.
  explicit FakeV4l2Device(FakeV4l2Config config);
  ~FakeV4l2Device() override;

  // A V4l2Device that forwards to `fake`, so a test can keep inspecting the fake after the
  // source that owns the handle is gone.
  static std::unique_ptr<V4l2Device> Handle(std::shared_ptr<FakeV4l2Device> fake);

  // The V4l2Device calls, answered like a driver would; misuse is recorded in violations().
  int Open(const std::string& path, int flags) override;
  int Close(int fd) override;
  int Ioctl(int fd, unsigned long request, void* arg) override;
  void* Mmap(size_t length, int fd, off_t offset) override;
  int Munmap(void* address, size_t length) override;
  int Poll(int fd, int timeout_ms) override;

  // Protocol violations by the caller, in order (empty when it behaved).
  const std::vector<std::string>& violations() const { return violations_; }
  // Frames that arrived while no buffer was queued (the caller starved the driver).
  uint64_t starved_frames() const { return starved_frames_; }
  // Every open() call, failed or not.
  int open_attempts() const { return open_attempts_; }
  // Descriptors open now.
  size_t open_descriptors() const { return descriptors_.size(); }
  // Buffer mappings not unmapped yet.
  size_t mappings() const;
  // Buffers the driver holds now (allocated by REQBUFS and not freed).
  size_t allocated_buffers() const { return buffers_.size(); }
  // Buffers queued to the driver or filled and waiting to be dequeued.
  size_t buffers_with_driver() const { return queued_.size() + done_.size(); }
  // Whether the driver is streaming now.
  bool streaming() const { return streaming_; }
  // VIDIOC_STREAMON and VIDIOC_STREAMOFF calls that succeeded.
  int streamon_calls() const { return streamon_calls_; }
  int streamoff_calls() const { return streamoff_calls_; }
  // The format the driver is set to now: pixel format, size and rate.
  uint32_t pixel_format() const { return format_.pixelformat; }
  cv::Size frame_size() const {
    return {static_cast<int>(format_.width), static_cast<int>(format_.height)};
  }
  double fps() const { return fps_; }
  // Every dequeued buffer, in order.
  const std::vector<FakeV4l2Delivery>& deliveries() const { return deliveries_; }
  // Script steps not used yet.
  size_t steps_left() const { return config_.script.size() - next_step_; }

 private:
  enum class BufferState { kWithCaller, kQueued, kDone };

  struct Buffer {
    std::shared_ptr<std::vector<uint8_t>> memory;
    uint32_t offset = 0;
    BufferState state = BufferState::kWithCaller;
    uint32_t bytesused = 0;
    uint32_t flags = 0;
    uint32_t sequence = 0;
    uint64_t tick = 0;
    FakeV4l2Step::Kind kind = FakeV4l2Step::Kind::kFrame;
    cv::Size size;
    uint32_t pixel_format = 0;
  };

  struct Mapping {
    std::shared_ptr<std::vector<uint8_t>> memory;
    size_t length = 0;
    int count = 0;
  };

  // Records a violation and sets errno to `error`; returns -1.
  int Violation(const std::string& what, int error);
  // Sets errno; returns -1.
  static int Fail(int error);
  // The driver's answer to each ioctl.
  int QueryCap(v4l2_capability* capability);
  // `refusable`: a size in refused_sizes fails (not when the driver resets itself).
  int SetFormat(v4l2_format* format, bool refusable = true);
  int GetFormat(v4l2_format* format);
  int SetParm(v4l2_streamparm* parm);
  int GetParm(v4l2_streamparm* parm);
  int EnumFrameSizes(v4l2_frmsizeenum* entry);
  int RequestBuffers(int fd, v4l2_requestbuffers* request);
  int QueryBuffer(v4l2_buffer* buffer);
  int QueueBuffer(int fd, v4l2_buffer* buffer);
  int DequeueBuffer(v4l2_buffer* buffer);
  int StreamOn(const int* type);
  int StreamOff(const int* type);
  // Fills the next queued buffer with the frame of `step`.
  void Produce(const FakeV4l2Step& step);
  // The device is unplugged: every descriptor goes stale and the driver state is lost.
  void Unplug(const FakeV4l2Step& step);
  // Forgets buffers, streaming and format state (a fresh driver instance).
  void ResetDriver();
  double HighestFps(uint32_t pixel_format) const;
  // The size S_FMT grants for `asked` in `pixel_format`.
  cv::Size GrantedSize(uint32_t pixel_format, cv::Size asked) const;
  bool AnyBufferMapped() const;

  FakeV4l2Config config_;
  int64_t monotonic_base_ns_ = 0;
  size_t next_step_ = 0;
  uint64_t tick_ = 0;
  uint32_t sequence_ = 0;

  // Device presence.
  bool gone_ = false;
  int reopen_failures_left_ = 0;
  int pending_loss_errno_ = 0;

  // Descriptors: fd -> stale (opened before the device was unplugged).
  std::map<int, bool> descriptors_;
  int next_fd_ = 100;

  // Driver state.
  v4l2_pix_format format_{};
  double fps_ = 0.0;
  std::vector<Buffer> buffers_;
  int owner_fd_ = -1;
  bool streaming_ = false;
  std::deque<uint32_t> queued_;
  std::deque<uint32_t> done_;
  uint32_t offset_base_ = 0;

  std::map<void*, Mapping> mappings_;
  std::vector<std::string> violations_;
  std::vector<FakeV4l2Delivery> deliveries_;
  uint64_t starved_frames_ = 0;
  int open_attempts_ = 0;
  int streamon_calls_ = 0;
  int streamoff_calls_ = 0;
};

}  // namespace silnet::node
