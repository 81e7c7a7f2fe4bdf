#include "node/capture/libcamera/libcamera_source.h"

#include <fmt/format.h>
#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/control_ids.h>
#include <libcamera/controls.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/pixel_format.h>
#include <libcamera/property_ids.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <iterator>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "shared/util/check.h"

namespace silnet::node {
namespace {

namespace formats = libcamera::formats;

// Pixel formats ConvertToBgr() handles, in order of preference.
constexpr libcamera::PixelFormat kConvertibleFormats[] = {
    formats::YUYV,   formats::MJPEG,    formats::NV12,    formats::RGB888,
    formats::BGR888, formats::UYVY,     formats::YVYU,    formats::NV21,
    formats::YUV420, formats::XRGB8888, formats::XBGR8888};

// A single-plane format cv::cvtColor turns into BGR.
struct PackedFormat {
  libcamera::PixelFormat format;
  int type;  // OpenCV type of one pixel (or, for 4:2:2, of one luma sample and its chroma)
  int code;  // cv::cvtColor code to BGR
};

// libcamera names packed RGB formats after DRM: RGB888 is stored B, G, R (OpenCV's BGR, taken
// as is elsewhere), BGR888 is stored R, G, B, XRGB8888 is B, G, R, X.
const PackedFormat kPackedFormats[] = {
    {formats::YUYV, CV_8UC2, cv::COLOR_YUV2BGR_YUYV},
    {formats::UYVY, CV_8UC2, cv::COLOR_YUV2BGR_UYVY},
    {formats::YVYU, CV_8UC2, cv::COLOR_YUV2BGR_YVYU},
    {formats::BGR888, CV_8UC3, cv::COLOR_RGB2BGR},
    {formats::XRGB8888, CV_8UC4, cv::COLOR_BGRA2BGR},
    {formats::XBGR8888, CV_8UC4, cv::COLOR_RGBA2BGR},
};

const PackedFormat* FindPacked(const libcamera::PixelFormat& format) {
  for (const PackedFormat& packed : kPackedFormats)
    if (packed.format == format) return &packed;
  return nullptr;
}

bool IsConvertible(const libcamera::PixelFormat& format) {
  return std::find(std::begin(kConvertibleFormats), std::end(kConvertibleFormats), format) !=
         std::end(kConvertibleFormats);
}

std::string FormatNames(const std::vector<libcamera::PixelFormat>& pixel_formats) {
  std::string names;
  for (const libcamera::PixelFormat& format : pixel_formats)
    names += (names.empty() ? "" : ", ") + format.toString();
  return names.empty() ? "none" : names;
}

std::string ErrnoText(int result) {
  return std::strerror(result < 0 ? -result : result);
}

// The process-wide CameraManager (libcamera allows one at a time). It is started on first use
// and stopped when the last user lets go; the mutex also orders that stop before a new start.
std::shared_ptr<libcamera::CameraManager> AcquireCameraManager() {
  struct Registry {
    std::mutex mutex;
    std::weak_ptr<libcamera::CameraManager> manager;
  };
  static Registry* const registry = new Registry();  // never destroyed: used by destructors
  std::lock_guard lock(registry->mutex);
  if (std::shared_ptr<libcamera::CameraManager> manager = registry->manager.lock()) return manager;
  auto manager = std::make_unique<libcamera::CameraManager>();
  const int result = manager->start();
  if (result < 0)
    throw CaptureError(
        fmt::format("libcamera could not start its camera manager: {}", ErrnoText(result)));
  std::shared_ptr<libcamera::CameraManager> shared(manager.release(),
                                                   [](libcamera::CameraManager* stopping) {
                                                     std::lock_guard stop_lock(registry->mutex);
                                                     stopping->stop();
                                                     delete stopping;
                                                   });
  registry->manager = shared;
  return shared;
}

// "id (model)" for every camera libcamera knows, or "none".
std::string CameraList(const std::vector<std::shared_ptr<libcamera::Camera>>& cameras) {
  std::string list;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const std::optional<std::string> model =
        cameras[i]->properties().get(libcamera::properties::Model);
    list += fmt::format("{}[{}] {}{}", i == 0 ? "" : ", ", i, cameras[i]->id(),
                        model ? fmt::format(" ({})", *model) : "");
  }
  return list.empty() ? "none" : list;
}

int64_t ClockNs(clockid_t clock) {
  timespec now{};
  clock_gettime(clock, &now);
  return static_cast<int64_t>(now.tv_sec) * 1000000000LL + now.tv_nsec;
}

// Converts a CLOCK_MONOTONIC instant to CLOCK_REALTIME with the clocks' current offset
// (sampled between two realtime readings to halve the sampling error).
int64_t MonotonicToRealtimeNs(int64_t monotonic_ns) {
  const int64_t before = ClockNs(CLOCK_REALTIME);
  const int64_t monotonic_now = ClockNs(CLOCK_MONOTONIC);
  const int64_t after = ClockNs(CLOCK_REALTIME);
  return monotonic_ns + (before + (after - before) / 2 - monotonic_now);
}

// One plane of a mapped frame buffer.
struct PlaneView {
  const uint8_t* data = nullptr;
  size_t length = 0;
};

// One mmap()ed dmabuf.
struct Mapping {
  void* address = nullptr;
  size_t length = 0;
};

// How an image lies in its planes.
struct ImageLayout {
  libcamera::PixelFormat format;
  int width = 0;
  int height = 0;
  size_t stride = 0;  // bytes per row of the first plane
};

ImageLayout LayoutOf(const libcamera::StreamConfiguration& config) {
  ImageLayout layout;
  layout.format = config.pixelFormat;
  layout.width = static_cast<int>(config.size.width);
  layout.height = static_cast<int>(config.size.height);
  layout.stride = config.stride;
  return layout;
}

// Buffers of the still-capture stream (few: the frames are large, and one still is taken at a
// time).
constexpr unsigned int kStillBuffers = 1;
// Still sizes tried (each with a fresh configuration) before stills fall back to the video.
constexpr size_t kStillAttempts = 3;
// Largest relative difference of aspect ratios taken as the same view.
constexpr double kAspectTolerance = 0.01;
// Frame sizes beyond this (in either dimension) are taken as "unbounded" range limits.
constexpr int64_t kLargestDimension = 1 << 16;

uint64_t Area(const libcamera::Size& size) {
  return uint64_t{size.width} * uint64_t{size.height};
}

// True if `size` has the aspect ratio of `reference` within kAspectTolerance.
bool SameAspect(const libcamera::Size& size, const libcamera::Size& reference) {
  if (size.height == 0 || reference.width == 0 || reference.height == 0) return false;
  const double ratio = (static_cast<double>(size.width) * reference.height) /
                       (static_cast<double>(size.height) * reference.width);
  return std::abs(ratio - 1.0) <= kAspectTolerance;
}

// The largest size of `range` (its minimum plus whole steps, up to its maximum) with the
// aspect ratio of `video`; a null size if there is none. A range StreamFormats made up from
// discrete sizes (steps 0) holds only those, which StreamFormats::sizes() lists: null too.
libcamera::Size LargestOfAspect(const libcamera::SizeRange& range, const libcamera::Size& video) {
  const libcamera::Size& min = range.min;
  const libcamera::Size& max = range.max;
  if (range.hStep == 0 || range.vStep == 0 || max.width == 0 || max.height == 0 ||
      min.width > max.width || min.height > max.height || video.width == 0 || video.height == 0)
    return libcamera::Size();
  const int64_t h_step = range.hStep;
  const int64_t v_step = range.vStep;
  const int64_t min_width = min.width;
  const int64_t min_height = min.height;
  const int64_t max_height = std::min<int64_t>(max.height, kLargestDimension);
  // No width beyond the one whose height of the video's aspect ratio passes the largest.
  const int64_t widest = std::min<int64_t>(
      {max.width, kLargestDimension, (max_height + v_step) * video.width / video.height + h_step});
  if (widest < min_width) return libcamera::Size();
  libcamera::Size best;
  uint64_t best_area = 0;
  // Widths from the widest down, while one can still give a larger area.
  for (int64_t width = min_width + (widest - min_width) / h_step * h_step;
       width >= min_width && width > 0; width -= h_step) {
    if (static_cast<uint64_t>(width) * static_cast<uint64_t>(max_height) <= best_area) break;
    const double ideal = static_cast<double>(width) * video.height / video.width;
    if (ideal < static_cast<double>(min_height)) break;  // narrower widths want lower heights
    const int64_t height = min_height + std::llround((ideal - static_cast<double>(min_height)) /
                                                     static_cast<double>(v_step)) *
                                            v_step;
    if (height > max_height) continue;
    const libcamera::Size size(static_cast<unsigned int>(width), static_cast<unsigned int>(height));
    if (SameAspect(size, video) && Area(size) > best_area) {
      best = size;
      best_area = Area(size);
    }
  }
  return best;
}

// A pixel format and size to ask of the still-capture stream.
struct StillCandidate {
  libcamera::PixelFormat format;
  libcamera::Size size;
};

// The sizes `formats` offers (its listed sizes and the largest of the video's aspect ratio in
// its range) in formats this source converts, larger than `video` and of its aspect ratio;
// largest first, on equal sizes in the order of kConvertibleFormats.
std::vector<StillCandidate> StillCandidates(const libcamera::StreamFormats& formats,
                                            const libcamera::Size& video) {
  const std::vector<libcamera::PixelFormat> offered = formats.pixelformats();
  std::vector<StillCandidate> candidates;
  for (const libcamera::PixelFormat& format : kConvertibleFormats) {
    if (std::find(offered.begin(), offered.end(), format) == offered.end()) continue;
    std::vector<libcamera::Size> sizes = formats.sizes(format);
    sizes.push_back(LargestOfAspect(formats.range(format), video));
    for (const libcamera::Size& size : sizes) {
      if (Area(size) <= Area(video) || !SameAspect(size, video)) continue;
      const bool known = std::any_of(
          candidates.begin(), candidates.end(),
          [&](const StillCandidate& c) { return c.format == format && c.size == size; });
      if (!known) candidates.push_back(StillCandidate{format, size});
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const StillCandidate& a, const StillCandidate& b) { return Area(a.size) > Area(b.size); });
  return candidates;
}

// A validated configuration of two streams: [0] the video exactly as `video` (validated alone)
// and [1] a still-capture stream larger than the video and of its aspect ratio. nullptr with
// `why` set when the camera cannot do that.
std::unique_ptr<libcamera::CameraConfiguration> StillConfiguration(
    libcamera::Camera& camera, const libcamera::StreamConfiguration& video, std::string* why) {
  const libcamera::StreamRoles roles = {libcamera::StreamRole::VideoRecording,
                                        libcamera::StreamRole::StillCapture};
  std::unique_ptr<libcamera::CameraConfiguration> config = camera.generateConfiguration(roles);
  if (!config || config->size() < 2) {
    *why = "the camera offers no still-capture stream beside the video";
    return nullptr;
  }
  const std::vector<StillCandidate> candidates =
      StillCandidates(config->at(1).formats(), video.size);
  if (candidates.empty()) {
    *why = fmt::format(
        "its still-capture stream offers no size larger than {} of the same aspect ratio in a "
        "pixel format this source converts",
        video.size.toString());
    return nullptr;
  }
  for (size_t attempt = 0; attempt < candidates.size() && attempt < kStillAttempts; ++attempt) {
    const StillCandidate& candidate = candidates[attempt];
    if (attempt > 0) {
      config = camera.generateConfiguration(roles);  // validate() may have changed the last one
      if (!config || config->size() < 2) {
        *why = "the camera offers no still-capture stream beside the video";
        return nullptr;
      }
    }
    libcamera::StreamConfiguration& both_video = config->at(0);
    libcamera::StreamConfiguration& still = config->at(1);
    both_video.pixelFormat = video.pixelFormat;
    both_video.size = video.size;
    both_video.bufferCount = video.bufferCount;
    both_video.colorSpace = video.colorSpace;
    still.pixelFormat = candidate.format;
    still.size = candidate.size;
    still.bufferCount = kStillBuffers;
    still.colorSpace = video.colorSpace;  // streams may have to share one: the video's
    const std::string asked =
        fmt::format("{}-{}", candidate.size.toString(), candidate.format.toString());
    if (config->validate() == libcamera::CameraConfiguration::Invalid) {
      *why = fmt::format("the camera rejects a still stream of {} beside the video", asked);
      continue;
    }
    if (config->size() < 2) {
      *why = "the camera cannot stream stills beside the video";
      return nullptr;
    }
    if (both_video.pixelFormat != video.pixelFormat || both_video.size != video.size ||
        both_video.bufferCount != video.bufferCount || both_video.colorSpace != video.colorSpace) {
      *why =
          fmt::format("with a still stream of {} the video would be {} {} instead of {} {}", asked,
                      both_video.toString(), libcamera::ColorSpace::toString(both_video.colorSpace),
                      video.toString(), libcamera::ColorSpace::toString(video.colorSpace));
      continue;
    }
    if (!IsConvertible(still.pixelFormat) || Area(still.size) <= Area(video.size) ||
        !SameAspect(still.size, video.size)) {
      *why = fmt::format("the camera makes a still stream of {} {}", asked, still.toString());
      continue;
    }
    return config;
  }
  return nullptr;
}

}  // namespace

// A still's planes copied out of its frame buffer, converted by TakeStill().
struct LibcameraSource::StillImage {
  std::vector<std::vector<uint8_t>> planes;
  std::optional<size_t> first_plane_used;  // bytes the camera filled, when it tells
  ImageLayout layout;
};

// Everything that exists only while the camera is open. The destructor tears it down in the
// order libcamera needs (stop, requests, buffers, release, camera, manager), so a half-done
// Open() cleans up by destroying it.
struct LibcameraSource::State {
  LibcameraSource* source = nullptr;  // for the still requests
  std::shared_ptr<libcamera::CameraManager> manager;
  std::shared_ptr<libcamera::Camera> camera;
  bool acquired = false;
  bool started = false;
  bool connected = false;
  std::unique_ptr<libcamera::CameraConfiguration> config;  // the video alone
  libcamera::Stream* stream = nullptr;
  libcamera::StreamConfiguration granted;

  // The still-capture stream, if configured (Read()'s thread).
  std::unique_ptr<libcamera::CameraConfiguration> still_config;  // video and still
  libcamera::Stream* still_stream = nullptr;
  libcamera::StreamConfiguration still_granted;
  std::vector<libcamera::FrameBuffer*> free_still_buffers;
  std::map<const libcamera::FrameBuffer*, uint64_t> still_in_flight;  // buffer -> still request
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator;
  std::vector<Mapping> mappings;
  std::map<const libcamera::FrameBuffer*, std::vector<PlaneView>> planes;
  std::vector<std::unique_ptr<libcamera::Request>> requests;
  std::optional<int64_t> frame_duration_us;  // set if the camera takes FrameDurationLimits
  size_t in_flight = 0;                      // requests queued to the camera (Read()'s thread)
  std::string requeue_error;

  // Sequence bookkeeping (Read()'s thread).
  bool have_sequence = false;
  uint32_t last_sequence = 0;
  uint64_t last_index = 0;

  // Filled by libcamera's thread, drained by Read().
  std::mutex mutex;
  std::condition_variable completed_cv;
  std::deque<libcamera::Request*> completed;
  bool disconnected = false;

  ~State();
  void OnRequestCompleted(libcamera::Request* request);
  void OnDisconnected();
  // Maps every plane of the allocated buffers; throws CaptureError if mmap fails.
  void MapBuffers(const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& buffers);
  // Configures the camera with `video` (validated alone) and a still-capture stream, allocates
  // and maps the still buffers; must come before the video buffers are mapped. False with `why`
  // set, and nothing of the still stream left, when the camera cannot; it must then be
  // configured for the video alone.
  bool ConfigureWithStill(const libcamera::StreamConfiguration& video, std::string* why);
  // Sets the per-request controls and queues `request`; returns libcamera's result.
  int Queue(libcamera::Request* request);
  // Gives a completed request back to the camera with its video buffer, dropping the still
  // buffer it carried and adding the free one if a still is requested.
  void Requeue(libcamera::Request* request, const std::string& camera_id);
  // Hands the still buffer of a completed request to the waiting TakeStill() and frees it.
  void DeliverStill(const libcamera::Request& request, libcamera::FrameBuffer* buffer);
  // Converts the buffer of a completed request to BGR; empty on failure with `error` set.
  cv::Mat ConvertToBgr(const libcamera::FrameBuffer& buffer, std::string* error) const;
};

LibcameraSource::State::~State() {
  if (started) camera->stop();  // cancels and completes every pending request
  if (connected) {
    camera->requestCompleted.disconnect(this);
    camera->disconnected.disconnect(this);
  }
  {
    std::lock_guard lock(mutex);
    completed.clear();
  }
  requests.clear();
  for (const Mapping& mapping : mappings)
    munmap(mapping.address, mapping.length);
  mappings.clear();
  planes.clear();
  allocator.reset();  // frees the buffers, which must precede release()
  if (acquired) camera->release();
  still_config.reset();
  config.reset();
  camera.reset();
  manager.reset();
}

void LibcameraSource::State::OnRequestCompleted(libcamera::Request* request) {
  {
    std::lock_guard lock(mutex);
    completed.push_back(request);
  }
  completed_cv.notify_one();
}

void LibcameraSource::State::OnDisconnected() {
  {
    std::lock_guard lock(mutex);
    disconnected = true;
  }
  completed_cv.notify_one();
  source->FailStills("the camera disconnected");
}

void LibcameraSource::State::MapBuffers(
    const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& buffers) {
  for (const std::unique_ptr<libcamera::FrameBuffer>& buffer : buffers) {
    // Planes often share one dmabuf at different offsets: map each dmabuf once, over all of
    // its planes.
    std::map<int, size_t> needed;
    for (const libcamera::FrameBuffer::Plane& plane : buffer->planes()) {
      if (plane.offset == libcamera::FrameBuffer::Plane::kInvalidOffset)
        throw CaptureError(
            fmt::format("camera {}: a frame buffer plane has no offset", camera->id()));
      size_t& length = needed[plane.fd.get()];
      length = std::max(length, static_cast<size_t>(plane.offset) + plane.length);
    }
    std::map<int, const uint8_t*> addresses;
    for (const auto& [fd, length] : needed) {
      const off_t size = lseek(fd, 0, SEEK_END);
      if (size > 0 && static_cast<size_t>(size) < length)
        throw CaptureError(
            fmt::format("camera {}: a frame buffer ({} bytes) is smaller than its "
                        "planes ({} bytes)",
                        camera->id(), size, length));
      void* address = mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, 0);
      if (address == MAP_FAILED)
        throw CaptureError(fmt::format("camera {}: cannot map a frame buffer: {}", camera->id(),
                                       ErrnoText(errno)));
      mappings.push_back(Mapping{address, length});
      addresses[fd] = static_cast<const uint8_t*>(address);
    }
    std::vector<PlaneView>& views = planes[buffer.get()];
    for (const libcamera::FrameBuffer::Plane& plane : buffer->planes())
      views.push_back(PlaneView{addresses[plane.fd.get()] + plane.offset, plane.length});
  }
}

bool LibcameraSource::State::ConfigureWithStill(const libcamera::StreamConfiguration& video,
                                                std::string* why) {
  std::unique_ptr<libcamera::CameraConfiguration> both = StillConfiguration(*camera, video, why);
  if (!both) return false;
  int result = camera->configure(both.get());
  if (result < 0) {
    *why = fmt::format("the camera cannot be configured with a still stream of {}: {}",
                       both->at(1).toString(), ErrnoText(result));
    return false;
  }
  libcamera::Stream* still = both->at(1).stream();
  if (both->at(0).stream() == nullptr || still == nullptr) {
    *why = "the camera gave no still stream";
    return false;
  }
  result = allocator->allocate(still);
  if (result <= 0) {
    allocator->free(still);
    *why = fmt::format("cannot allocate still buffers: {}",
                       result < 0 ? ErrnoText(result) : "none allocated");
    return false;
  }
  const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& buffers = allocator->buffers(still);
  try {
    MapBuffers(buffers);
  } catch (const CaptureError& e) {
    for (const Mapping& mapping : mappings)  // only still buffers are mapped so far
      munmap(mapping.address, mapping.length);
    mappings.clear();
    planes.clear();
    allocator->free(still);
    *why = e.what();
    return false;
  }
  for (const std::unique_ptr<libcamera::FrameBuffer>& buffer : buffers)
    free_still_buffers.push_back(buffer.get());
  still_stream = still;
  still_granted = still->configuration();  // what configure() settled on
  still_config = std::move(both);
  return true;
}

int LibcameraSource::State::Queue(libcamera::Request* request) {
  if (frame_duration_us) {
    request->controls().set(libcamera::controls::FrameDurationLimits,
                            {*frame_duration_us, *frame_duration_us});
  }
  const int result = camera->queueRequest(request);
  if (result >= 0) ++in_flight;
  return result;
}

void LibcameraSource::State::Requeue(libcamera::Request* request, const std::string& camera_id) {
  if (still_stream != nullptr && request->findBuffer(still_stream) != nullptr) {
    // reuse(ReuseBuffers) would keep the still buffer: start empty with the video buffer.
    libcamera::FrameBuffer* video = request->findBuffer(stream);
    request->reuse(libcamera::Request::Default);
    if (video != nullptr) {
      const int result = request->addBuffer(stream, video);
      if (result < 0) {
        requeue_error = fmt::format("cannot put the frame buffer back: {}", ErrnoText(result));
        spdlog::warn("libcamera camera {}: cannot re-queue a request: {}", camera_id,
                     requeue_error);
        return;
      }
    }
  } else {
    request->reuse(libcamera::Request::ReuseBuffers);
  }

  // A requested still rides on this request.
  uint64_t still_id = 0;
  libcamera::FrameBuffer* still = nullptr;
  if (still_stream != nullptr && !free_still_buffers.empty()) {
    still_id = source->TakeStillRequest();
    if (still_id != 0) {
      still = free_still_buffers.back();
      const int result = request->addBuffer(still_stream, still);
      if (result < 0) {
        source->AnswerStill(
            still_id, nullptr,
            fmt::format("libcamera camera {}: cannot add the still buffer to a request: {}",
                        camera_id, ErrnoText(result)));
        still = nullptr;
      } else {
        free_still_buffers.pop_back();
        still_in_flight[still] = still_id;
      }
    }
  }

  const int result = Queue(request);
  if (result < 0) {
    requeue_error = ErrnoText(result);
    spdlog::warn("libcamera camera {}: cannot re-queue a request: {}", camera_id, requeue_error);
    if (still != nullptr) {
      still_in_flight.erase(still);
      free_still_buffers.push_back(still);
      source->AnswerStill(still_id, nullptr,
                          fmt::format("libcamera camera {}: cannot queue the still request: {}",
                                      camera_id, requeue_error));
    }
  }
}

void LibcameraSource::State::DeliverStill(const libcamera::Request& request,
                                          libcamera::FrameBuffer* buffer) {
  const auto found = still_in_flight.find(buffer);
  if (found == still_in_flight.end()) return;  // not one this source attached
  const uint64_t id = found->second;
  still_in_flight.erase(found);
  std::shared_ptr<StillImage> image;
  std::string error;
  const libcamera::FrameMetadata& metadata = buffer->metadata();
  if (!source->StillAwaited(id)) {
    // Its TakeStill() gave up: nothing to copy.
  } else if (request.status() == libcamera::Request::RequestCancelled ||
             metadata.status == libcamera::FrameMetadata::FrameCancelled) {
    error = "the still was cancelled";
  } else if (metadata.status != libcamera::FrameMetadata::FrameSuccess) {
    error = "the still frame failed";
  } else if (const auto views = planes.find(buffer); views == planes.end()) {
    error = "the completed still buffer is not one of the allocated buffers";
  } else {
    // Copied so that the buffer goes back at once and TakeStill() converts on its own thread.
    image = std::make_shared<StillImage>();
    for (const PlaneView& view : views->second)
      image->planes.emplace_back(view.data, view.data + view.length);
    if (!metadata.planes().empty()) image->first_plane_used = metadata.planes()[0].bytesused;
    image->layout = LayoutOf(still_granted);
  }
  free_still_buffers.push_back(buffer);
  source->AnswerStill(
      id, std::move(image),
      error.empty() ? "" : fmt::format("libcamera camera {}: {}", camera->id(), error));
}

namespace {

// Converts an image laid out as `layout` in `views` to BGR; empty on failure with `error` set.
// `first_plane_used` is the bytes the camera filled in the first plane, when it tells.
cv::Mat ConvertPlanes(const std::vector<PlaneView>& views, std::optional<size_t> first_plane_used,
                      const ImageLayout& layout, std::string* error) {
  const libcamera::PixelFormat format = layout.format;
  const int width = layout.width;
  const int height = layout.height;
  const size_t stride = layout.stride;

  // Plane `index` from `byte_offset` on as `rows` x `cols` of `type`, rows `step` bytes
  // apart; empty if that does not fit in the plane.
  auto plane_mat = [&](size_t index, size_t byte_offset, int rows, int cols, int type,
                       size_t step) -> cv::Mat {
    if (index >= views.size() || rows <= 0 || cols <= 0) return cv::Mat();
    const size_t row_bytes = static_cast<size_t>(cols) * static_cast<size_t>(CV_ELEM_SIZE(type));
    if (step < row_bytes) return cv::Mat();
    const size_t needed = byte_offset + step * static_cast<size_t>(rows - 1) + row_bytes;
    if (needed > views[index].length) return cv::Mat();
    return cv::Mat(rows, cols, type, const_cast<uint8_t*>(views[index].data + byte_offset), step);
  };

  cv::Mat bgr;
  try {
    if (format == formats::MJPEG) {
      size_t used = views.empty() ? 0 : views[0].length;
      if (first_plane_used) used = std::min(used, *first_plane_used);
      if (used == 0) {
        *error = "empty MJPEG frame";
        return cv::Mat();
      }
      const cv::Mat encoded(1, static_cast<int>(used), CV_8UC1,
                            const_cast<uint8_t*>(views[0].data));
      bgr = cv::imdecode(encoded, cv::IMREAD_COLOR);
      if (bgr.empty() || bgr.cols != width || bgr.rows != height) {
        *error = bgr.empty() ? "corrupt MJPEG frame"
                             : fmt::format("MJPEG frame is {}x{}, expected {}x{}", bgr.cols,
                                           bgr.rows, width, height);
        return cv::Mat();
      }
      return bgr;
    }

    const PackedFormat* packed = FindPacked(format);
    if (format == formats::RGB888) {
      // libcamera's RGB888 is stored B, G, R: OpenCV's BGR as is.
      const cv::Mat view = plane_mat(0, 0, height, width, CV_8UC3, stride);
      if (!view.empty()) bgr = view.clone();
    } else if (packed != nullptr) {
      const cv::Mat view = plane_mat(0, 0, height, width, packed->type, stride);
      if (!view.empty()) cv::cvtColor(view, bgr, packed->code);
    } else if (format == formats::NV12 || format == formats::NV21) {
      // Chroma follows luma in the same plane when the buffer has a single plane.
      const cv::Mat luma = plane_mat(0, 0, height, width, CV_8UC1, stride);
      const cv::Mat chroma =
          views.size() > 1 ? plane_mat(1, 0, height / 2, width / 2, CV_8UC2, stride)
                           : plane_mat(0, stride * height, height / 2, width / 2, CV_8UC2, stride);
      if (!luma.empty() && !chroma.empty()) {
        cv::cvtColorTwoPlane(
            luma, chroma, bgr,
            format == formats::NV12 ? cv::COLOR_YUV2BGR_NV12 : cv::COLOR_YUV2BGR_NV21);
      }
    } else if (format == formats::YUV420) {
      // Three planes (or one holding all three); chroma rows are half the luma stride apart.
      const size_t chroma_stride = stride / 2;
      const size_t luma_bytes = stride * height;
      const size_t chroma_bytes = chroma_stride * (height / 2);
      const bool split = views.size() >= 3;
      const cv::Mat luma = plane_mat(0, 0, height, width, CV_8UC1, stride);
      const cv::Mat u = plane_mat(split ? 1 : 0, split ? 0 : luma_bytes, height / 2, width / 2,
                                  CV_8UC1, chroma_stride);
      const cv::Mat v = plane_mat(split ? 2 : 0, split ? 0 : luma_bytes + chroma_bytes, height / 2,
                                  width / 2, CV_8UC1, chroma_stride);
      if (!luma.empty() && !u.empty() && !v.empty()) {
        // cvtColor wants I420 without padding: the luma rows, then all of U, then all of V.
        cv::Mat i420(height + height / 2, width, CV_8UC1);
        luma.copyTo(i420.rowRange(0, height));
        const size_t chroma_size = static_cast<size_t>(width / 2) * static_cast<size_t>(height / 2);
        cv::Mat u_packed(height / 2, width / 2, CV_8UC1, i420.ptr(height));
        cv::Mat v_packed(height / 2, width / 2, CV_8UC1, i420.ptr(height) + chroma_size);
        u.copyTo(u_packed);
        v.copyTo(v_packed);
        cv::cvtColor(i420, bgr, cv::COLOR_YUV2BGR_I420);
      }
    } else {
      *error = fmt::format("pixel format {} cannot be converted", format.toString());
      return cv::Mat();
    }
  } catch (const cv::Exception& e) {
    *error = fmt::format("conversion from {} failed: {}", format.toString(), e.what());
    return cv::Mat();
  }
  if (bgr.empty()) {
    *error = fmt::format("{} frame buffer is smaller than {}x{} with stride {}", format.toString(),
                         width, height, stride);
  }
  return bgr;
}

}  // namespace

cv::Mat LibcameraSource::State::ConvertToBgr(const libcamera::FrameBuffer& buffer,
                                             std::string* error) const {
  const auto found = planes.find(&buffer);
  if (found == planes.end()) {
    *error = "completed buffer is not one of the allocated buffers";
    return cv::Mat();
  }
  const libcamera::FrameMetadata& metadata = buffer.metadata();
  std::optional<size_t> first_plane_used;
  if (!metadata.planes().empty()) first_plane_used = metadata.planes()[0].bytesused;
  return ConvertPlanes(found->second, first_plane_used, LayoutOf(granted), error);
}

LibcameraSource::LibcameraSource(LibcameraSourceOptions options)
    : options_(std::move(options)), still_camera_(RequestedCamera()) {}

LibcameraSource::~LibcameraSource() {
  Close();
}

void LibcameraSource::Open() {
  Close();
  format_ = CaptureFormat{};
  camera_id_.clear();
  if (options_.width < 0 || options_.height < 0 || (options_.width == 0) != (options_.height == 0))
    throw CaptureError("libcamera: give both width and height, or neither");
  if (!std::isfinite(options_.fps) || options_.fps < 0.0)
    throw CaptureError(fmt::format("libcamera: bad frame rate {}", options_.fps));
  if (options_.buffer_count < 0)
    throw CaptureError(fmt::format("libcamera: bad buffer count {}", options_.buffer_count));
  if (options_.still_timeout.count() <= 0)
    throw CaptureError("libcamera: the still timeout must be positive");

  auto state = std::make_unique<State>();
  state->source = this;
  state->manager = AcquireCameraManager();
  const std::vector<std::shared_ptr<libcamera::Camera>> cameras = state->manager->cameras();
  const std::string wanted = options_.camera_id.empty()
                                 ? fmt::format("camera index {}", options_.camera_index)
                                 : fmt::format("camera id '{}'", options_.camera_id);
  if (cameras.empty())
    throw CaptureError(
        fmt::format("libcamera found no camera (asked for {}); cameras: none", wanted));
  if (!options_.camera_id.empty()) {
    for (const std::shared_ptr<libcamera::Camera>& camera : cameras)
      if (camera->id() == options_.camera_id) state->camera = camera;
  } else if (options_.camera_index >= 0 &&
             static_cast<size_t>(options_.camera_index) < cameras.size()) {
    state->camera = cameras[static_cast<size_t>(options_.camera_index)];
  }
  if (!state->camera)
    throw CaptureError(
        fmt::format("libcamera has no {}; cameras: {}", wanted, CameraList(cameras)));
  libcamera::Camera& camera = *state->camera;
  const std::string id = camera.id();

  int result = camera.acquire();
  if (result < 0)
    throw CaptureError(fmt::format("libcamera camera {} is busy (in use by another program?): {}",
                                   id, ErrnoText(result)));
  state->acquired = true;

  state->config = camera.generateConfiguration({libcamera::StreamRole::VideoRecording});
  if (!state->config || state->config->empty())
    throw CaptureError(fmt::format("libcamera camera {} cannot record video", id));
  libcamera::StreamConfiguration& stream_config = state->config->at(0);
  const std::vector<libcamera::PixelFormat> offered = stream_config.formats().pixelformats();
  libcamera::PixelFormat chosen;
  if (!options_.pixel_format.empty()) {
    chosen = libcamera::PixelFormat::fromString(options_.pixel_format);
    if (!chosen.isValid() || !IsConvertible(chosen))
      throw CaptureError(
          fmt::format("libcamera: pixel format '{}' is not one this source "
                      "converts ({})",
                      options_.pixel_format,
                      FormatNames(std::vector<libcamera::PixelFormat>(
                          std::begin(kConvertibleFormats), std::end(kConvertibleFormats)))));
    if (std::find(offered.begin(), offered.end(), chosen) == offered.end())
      throw CaptureError(fmt::format("libcamera camera {} does not offer {}; it offers {}", id,
                                     chosen.toString(), FormatNames(offered)));
  } else {
    for (const libcamera::PixelFormat& format : kConvertibleFormats) {
      if (std::find(offered.begin(), offered.end(), format) != offered.end()) {
        chosen = format;
        break;
      }
    }
    if (!chosen.isValid())
      throw CaptureError(
          fmt::format("libcamera camera {} offers no pixel format this source "
                      "converts; it offers {}",
                      id, FormatNames(offered)));
  }
  stream_config.pixelFormat = chosen;
  if (options_.width > 0) {
    stream_config.size = libcamera::Size(static_cast<unsigned int>(options_.width),
                                         static_cast<unsigned int>(options_.height));
  }
  if (options_.buffer_count > 0)
    stream_config.bufferCount = static_cast<unsigned int>(options_.buffer_count);

  const libcamera::CameraConfiguration::Status status = state->config->validate();
  if (status == libcamera::CameraConfiguration::Invalid)
    throw CaptureError(fmt::format("libcamera camera {} rejects {} {}x{}", id, chosen.toString(),
                                   options_.width, options_.height));
  if (!IsConvertible(stream_config.pixelFormat))
    throw CaptureError(
        fmt::format("libcamera camera {} grants {} instead of {}, which this source "
                    "cannot convert",
                    id, stream_config.pixelFormat.toString(), chosen.toString()));
  if (status == libcamera::CameraConfiguration::Adjusted) {
    spdlog::info("libcamera camera {}: asked for {} {}x{}, granted {}", id, chosen.toString(),
                 options_.width, options_.height, stream_config.toString());
  }
  state->allocator = std::make_unique<libcamera::FrameBufferAllocator>(state->camera);
  bool with_still = false;
  if (options_.still_capture) {
    std::string no_still;
    with_still = state->ConfigureWithStill(stream_config, &no_still);
    if (with_still) {
      spdlog::info("libcamera camera {}: stills at {} from a still-capture stream", id,
                   state->still_granted.toString());
    } else {
      spdlog::info("libcamera camera {}: {}; stills are the video frames", id, no_still);
    }
  }
  if (with_still) {
    state->stream = state->still_config->at(0).stream();
  } else {
    result = camera.configure(state->config.get());
    if (result < 0)
      throw CaptureError(fmt::format("libcamera camera {} cannot be configured as {}: {}", id,
                                     stream_config.toString(), ErrnoText(result)));
    state->stream = stream_config.stream();
  }
  if (state->stream == nullptr)
    throw CaptureError(fmt::format("libcamera camera {} gave no stream", id));
  state->granted = state->stream->configuration();  // what configure() settled on

  result = state->allocator->allocate(state->stream);
  if (result <= 0)
    throw CaptureError(fmt::format("libcamera camera {}: cannot allocate frame buffers: {}", id,
                                   result < 0 ? ErrnoText(result) : "none allocated"));
  const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& buffers =
      state->allocator->buffers(state->stream);
  state->MapBuffers(buffers);
  for (size_t i = 0; i < buffers.size(); ++i) {
    std::unique_ptr<libcamera::Request> request = camera.createRequest(i);
    if (!request)
      throw CaptureError(fmt::format("libcamera camera {}: cannot create a request", id));
    result = request->addBuffer(state->stream, buffers[i].get());
    if (result < 0)
      throw CaptureError(fmt::format("libcamera camera {}: cannot attach a buffer to a request: {}",
                                     id, ErrnoText(result)));
    state->requests.push_back(std::move(request));
  }

  // The frame rate, through FrameDurationLimits (microseconds) within the camera's range.
  const libcamera::ControlInfoMap& controls = camera.controls();
  const auto limits = controls.find(libcamera::controls::FrameDurationLimits.id());
  if (options_.fps > 0.0 && limits != controls.end()) {
    int64_t duration_us = std::llround(1e6 / options_.fps);
    const libcamera::ControlValue& min = limits->second.min();
    const libcamera::ControlValue& max = limits->second.max();
    if (min.type() == libcamera::ControlTypeInteger64 && !min.isArray())
      duration_us = std::max(duration_us, min.get<int64_t>());
    if (max.type() == libcamera::ControlTypeInteger64 && !max.isArray() && max.get<int64_t>() > 0)
      duration_us = std::min(duration_us, max.get<int64_t>());
    if (with_still && duration_us > std::llround(1e6 / options_.fps)) {
      spdlog::warn("libcamera camera {}: with its still stream it runs at most {:g} fps, not {:g}",
                   id, 1e6 / static_cast<double>(duration_us), options_.fps);
    }
    state->frame_duration_us = duration_us;
    format_.fps = 1e6 / static_cast<double>(duration_us);
  } else if (options_.fps > 0.0) {
    spdlog::warn(
        "libcamera camera {} does not take frame duration limits; it runs at its own "
        "rate, not {} fps",
        id, options_.fps);
  }

  camera.requestCompleted.connect(state.get(), &State::OnRequestCompleted);
  camera.disconnected.connect(state.get(), &State::OnDisconnected);
  state->connected = true;

  libcamera::ControlList start_controls(controls);
  if (state->frame_duration_us) {
    start_controls.set(libcamera::controls::FrameDurationLimits,
                       {*state->frame_duration_us, *state->frame_duration_us});
  }
  result = camera.start(&start_controls);
  if (result < 0)
    throw CaptureError(
        fmt::format("libcamera camera {} cannot start streaming: {}", id, ErrnoText(result)));
  state->started = true;
  for (const std::unique_ptr<libcamera::Request>& request : state->requests) {
    result = state->Queue(request.get());
    if (result < 0)
      throw CaptureError(
          fmt::format("libcamera camera {}: cannot queue a request: {}", id, ErrnoText(result)));
  }

  format_.width = static_cast<int>(state->granted.size.width);
  format_.height = static_cast<int>(state->granted.size.height);
  format_.pixel_format = state->granted.pixelFormat.toString();
  camera_id_ = id;
  state_ = std::move(state);
  std::lock_guard lock(still_mutex_);
  still_camera_ = id;
  accepting_stills_ = true;
  still_stream_ = with_still;
}

CaptureStatus LibcameraSource::Read(CapturedFrame* frame, std::chrono::milliseconds timeout) {
  SILNET_CHECK_MSG(state_ != nullptr, "LibcameraSource::Read() before Open()");
  SILNET_CHECK(frame != nullptr);
  State& state = *state_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    libcamera::Request* request = nullptr;
    {
      std::unique_lock lock(state.mutex);
      state.completed_cv.wait_until(lock, deadline,
                                    [&] { return !state.completed.empty() || state.disconnected; });
      if (state.completed.empty()) {
        if (state.disconnected) {
          last_error_ = fmt::format("libcamera camera {} disconnected", camera_id_);
          ++counters_.errors;
          return CaptureStatus::kError;
        }
        if (state.in_flight == 0 && !state.requeue_error.empty()) {
          last_error_ = fmt::format("libcamera camera {} has no request left to fill: {}",
                                    camera_id_, state.requeue_error);
          ++counters_.errors;
          return CaptureStatus::kError;
        }
        return CaptureStatus::kTimeout;
      }
      request = state.completed.front();
      state.completed.pop_front();
    }
    --state.in_flight;
    if (state.still_stream != nullptr) {
      if (libcamera::FrameBuffer* still = request->findBuffer(state.still_stream))
        state.DeliverStill(*request, still);
    }

    // Gives the request back to the camera with the same buffer (and a requested still's).
    auto requeue = [&] { state.Requeue(request, camera_id_); };

    if (request->status() == libcamera::Request::RequestCancelled) {
      requeue();
      if (std::chrono::steady_clock::now() >= deadline) return CaptureStatus::kTimeout;
      continue;
    }
    const libcamera::FrameBuffer* buffer = request->findBuffer(state.stream);
    if (buffer == nullptr) {
      requeue();
      continue;
    }
    const libcamera::FrameMetadata& metadata = buffer->metadata();

    // Frame index from the sequence number (32 bits, may wrap), counted from the first frame.
    uint64_t index = 0;
    if (state.have_sequence) {
      index = state.last_index + static_cast<uint32_t>(metadata.sequence - state.last_sequence);
      if (index > state.last_index + 1) counters_.dropped += index - state.last_index - 1;
    }
    state.have_sequence = true;
    state.last_sequence = metadata.sequence;
    state.last_index = index;

    const std::optional<int64_t> sensor_ns =
        request->metadata().get(libcamera::controls::SensorTimestamp);
    const int64_t monotonic_ns =
        sensor_ns && *sensor_ns > 0 ? *sensor_ns : static_cast<int64_t>(metadata.timestamp);
    frame->frame_index = index;
    frame->capture_time_ns =
        monotonic_ns > 0 ? MonotonicToRealtimeNs(monotonic_ns) : RealtimeNowNs();

    std::string error;
    cv::Mat image;
    if (metadata.status != libcamera::FrameMetadata::FrameSuccess) {
      error = metadata.status == libcamera::FrameMetadata::FrameCancelled ? "frame cancelled"
                                                                          : "frame failed";
    } else {
      image = state.ConvertToBgr(*buffer, &error);
    }
    requeue();
    if (image.empty()) {
      frame->image = cv::Mat();
      last_error_ = fmt::format("libcamera camera {}: frame {}: {}", camera_id_, index, error);
      ++counters_.errors;
      ++counters_.dropped;
      return CaptureStatus::kFrameError;
    }
    frame->image = std::move(image);
    ++counters_.frames;
    return CaptureStatus::kFrame;
  }
}

void LibcameraSource::Close() {
  {
    std::lock_guard lock(still_mutex_);
    if (waiting_still_id_ != 0 && still_answer_.id != waiting_still_id_) {
      still_answer_ = StillAnswer{waiting_still_id_, nullptr,
                                  StillMessage("the source was closed while a still waited")};
    }
    accepting_stills_ = false;
    still_stream_ = false;
    still_failure_.clear();
    pending_still_id_ = 0;
  }
  still_answered_.notify_all();
  state_.reset();
}

std::optional<StillPhoto> LibcameraSource::TakeStill(const CapturedFrame& frame) {
  static_cast<void>(frame);
  if (!options_.still_capture) return std::nullopt;
  std::lock_guard call(still_call_mutex_);
  std::unique_lock lock(still_mutex_);
  if (!accepting_stills_) throw CaptureError(StillMessage("no still: the source is not open"));
  if (!still_stream_) return std::nullopt;
  if (!still_failure_.empty())
    throw CaptureError(StillMessage(fmt::format("no still: {}", still_failure_)));
  const uint64_t id = ++last_still_id_;
  pending_still_id_ = id;
  waiting_still_id_ = id;
  const bool answered =
      still_answered_.wait_until(lock, std::chrono::steady_clock::now() + options_.still_timeout,
                                 [&] { return still_answer_.id == id; });
  waiting_still_id_ = 0;
  if (!answered) {
    if (pending_still_id_ == id) pending_still_id_ = 0;
    throw CaptureError(
        StillMessage(fmt::format("no still within {} ms", options_.still_timeout.count())));
  }
  StillAnswer answer = std::move(still_answer_);
  still_answer_ = StillAnswer{};
  const std::string camera = still_camera_;
  lock.unlock();
  if (!answer.error.empty()) throw CaptureError(answer.error);
  if (!answer.image) throw CaptureError(fmt::format("libcamera camera {}: no still", camera));

  const StillImage& image = *answer.image;
  std::vector<PlaneView> views;
  for (const std::vector<uint8_t>& plane : image.planes)
    views.push_back(PlaneView{plane.data(), plane.size()});
  std::string error;
  StillPhoto still;
  still.photo = ConvertPlanes(views, image.first_plane_used, image.layout, &error);
  if (still.photo.empty())
    throw CaptureError(fmt::format("libcamera camera {}: still: {}", camera, error));
  return still;
}

std::string LibcameraSource::RequestedCamera() const {
  return options_.camera_id.empty() ? fmt::format("#{}", options_.camera_index)
                                    : options_.camera_id;
}

std::string LibcameraSource::StillMessage(const std::string& message) const {
  return fmt::format("libcamera camera {}: {}", still_camera_, message);
}

uint64_t LibcameraSource::TakeStillRequest() {
  std::lock_guard lock(still_mutex_);
  return std::exchange(pending_still_id_, 0);
}

bool LibcameraSource::StillAwaited(uint64_t id) {
  std::lock_guard lock(still_mutex_);
  return waiting_still_id_ == id;
}

void LibcameraSource::AnswerStill(uint64_t id, std::shared_ptr<const StillImage> image,
                                  std::string error) {
  {
    std::lock_guard lock(still_mutex_);
    if (waiting_still_id_ != id) return;  // the caller gave up
    still_answer_ = StillAnswer{id, std::move(image), std::move(error)};
  }
  still_answered_.notify_all();
}

void LibcameraSource::FailStills(const std::string& reason) {
  {
    std::lock_guard lock(still_mutex_);
    still_failure_ = reason;
    pending_still_id_ = 0;
    if (waiting_still_id_ != 0 && still_answer_.id != waiting_still_id_) {
      still_answer_ = StillAnswer{waiting_still_id_, nullptr,
                                  StillMessage(fmt::format("no still: {}", reason))};
    }
  }
  still_answered_.notify_all();
}

std::string LibcameraSource::Describe() const {
  const std::string camera = camera_id_.empty() ? RequestedCamera() : camera_id_;
  return fmt::format("libcamera:{} {}x{} {} {}", camera, format_.width, format_.height,
                     format_.pixel_format,
                     format_.fps > 0.0 ? fmt::format("{:g} fps", format_.fps) : "fps unknown");
}

}  // namespace silnet::node
