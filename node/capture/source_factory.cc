#include "node/capture/source_factory.h"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>

#include "node/capture/files/image_folder_source.h"
#include "node/capture/files/video_file_source.h"
#include "node/capture/v4l2/v4l2_source.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/dataset_layout.h"
#ifdef SILNET_HAVE_LIBCAMERA
#include "node/capture/libcamera/libcamera_source.h"
#endif

namespace silnet::node {
namespace {

constexpr const char* kKinds = "v4l2, libcamera, video, images, masks, sim or sim-masks";

// A simulated camera: a dataset camera's images replayed as a live source. When the dataset
// has a statue stills folder (`silnet-sim stills --cameras-from`), its still stream shows the
// statue at that folder's resolution, with the empty room as the still's background.
class SimulatedCameraSource : public CaptureSource {
 public:
  SimulatedCameraSource(std::unique_ptr<ImageFolderSource> images, std::string description,
                        std::filesystem::path still, std::filesystem::path still_background)
      : images_(std::move(images)),
        description_(std::move(description)),
        still_(std::move(still)),
        still_background_(std::move(still_background)) {}
  void Open() override { images_->Open(); }
  CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) override {
    return images_->Read(frame, timeout);
  }
  void Close() override { images_->Close(); }
  CaptureFormat Format() const override { return images_->Format(); }
  std::string Kind() const override { return "sim"; }
  std::string Describe() const override { return description_ + " (" + images_->Describe() + ")"; }
  std::string LastError() const override { return images_->LastError(); }
  CaptureCounters Counters() const override { return images_->Counters(); }
  std::optional<StillPhoto> TakeStill(const CapturedFrame&) override {
    if (!std::filesystem::exists(still_)) return std::nullopt;
    StillPhoto still;
    still.photo = cv::imread(still_.string(), cv::IMREAD_COLOR);
    if (still.photo.empty()) throw CaptureError("cannot read the still " + still_.string());
    if (std::filesystem::exists(still_background_)) {
      still.background = cv::imread(still_background_.string(), cv::IMREAD_COLOR);
      if (still.background.size() != still.photo.size())
        throw CaptureError("the still's background " + still_background_.string() +
                           " is unreadable or of another size");
    }
    return still;
  }

 private:
  std::unique_ptr<ImageFolderSource> images_;
  std::string description_;
  std::filesystem::path still_, still_background_;
};

std::unique_ptr<CaptureSource> MakeSimulatedCamera(const std::filesystem::path& camera_dir,
                                                   bool masks, const SourceOptions& options) {
  const std::filesystem::path dataset = camera_dir.parent_path();
  const std::string camera_id = camera_dir.filename().string();
  const std::vector<CameraModel> cameras =
      LoadCalibration(DatasetLayout(dataset).GroundTruthPath());
  const auto it = std::find_if(cameras.begin(), cameras.end(),
                               [&](const CameraModel& c) { return c.id == camera_id; });
  if (it == cameras.end()) {
    throw InputError("camera '" + camera_id + "' is not in " + dataset.string() +
                     "/ground_truth.yaml");
  }
  if (!(options.speed > 0.0)) throw InputError("replay speed must be positive");
  ImageFolderSourceOptions o;
  o.folder = masks ? DatasetLayout(dataset).MasksDir(camera_id)
                   : DatasetLayout(dataset).FramesDir(camera_id);
  o.masks = masks;
  o.fps = it->fps * options.speed;
  o.real_time = true;
  o.start_ns = options.start_ns;
  o.offset_frames = it->time_offset;
  const std::filesystem::path statue = dataset / "statue" / camera_id;
  return std::make_unique<SimulatedCameraSource>(
      std::make_unique<ImageFolderSource>(o), "sim:" + camera_dir.string(),
      statue / "stills" / DatasetLayout::ImageName(0), statue / "background.png");
}

}  // namespace

SourceDescription ParseSourceDescription(const std::string& text) {
  const size_t colon = text.find(':');
  SourceDescription d;
  if (colon != std::string::npos) {
    d.kind = text.substr(0, colon);
    d.location = text.substr(colon + 1);
  }
  static const std::vector<std::string> kinds = {"v4l2",  "libcamera", "video",    "images",
                                                 "masks", "sim",       "sim-masks"};
  if (std::find(kinds.begin(), kinds.end(), d.kind) == kinds.end() ||
      (d.location.empty() && d.kind != "libcamera")) {
    throw InputError("capture source '" + text + "' must look like kind:location with kind " +
                     kKinds);
  }
  return d;
}

std::unique_ptr<CaptureSource> MakeCaptureSource(const SourceDescription& d,
                                                 const SourceOptions& o) {
  if (d.kind == "v4l2") {
    V4l2SourceOptions v;
    v.device = d.location;
    v.width = o.width;
    v.height = o.height;
    v.fps = o.fps;
    if (o.pixel_format == "yuyv") {
      v.pixel_format = V4l2PixelFormat::kYuyv;
    } else if (o.pixel_format == "mjpeg") {
      v.pixel_format = V4l2PixelFormat::kMjpeg;
    } else if (o.pixel_format != "auto") {
      throw InputError("pixel format must be yuyv, mjpeg or auto, not '" + o.pixel_format + "'");
    }
    v.full_resolution_stills = !o.video_stills;
    return std::make_unique<V4l2Source>(v);
  }
  if (d.kind == "libcamera") {
#ifdef SILNET_HAVE_LIBCAMERA
    LibcameraSourceOptions l;
    if (!d.location.empty() && d.location[0] == '#') {
      l.camera_index = std::stoi(d.location.substr(1));
    } else {
      l.camera_id = d.location;
    }
    l.width = o.width;
    l.height = o.height;
    l.fps = o.fps;
    l.still_capture = !o.video_stills;
    return std::make_unique<LibcameraSource>(l);
#else
    throw InputError("this silnet-node was built without libcamera");
#endif
  }
  if (d.kind == "video") {
    VideoFileSourceOptions v;
    v.file = d.location;
    v.fps = o.real_time ? o.fps : 0.0;
    v.real_time = o.real_time;
    v.start_ns = o.start_ns;
    return std::make_unique<VideoFileSource>(v);
  }
  if (d.kind == "images" || d.kind == "masks") {
    ImageFolderSourceOptions i;
    i.folder = d.location;
    i.masks = d.masks();
    i.fps = o.fps;
    i.real_time = o.real_time;
    i.start_ns = o.start_ns;
    return std::make_unique<ImageFolderSource>(i);
  }
  std::filesystem::path camera_dir = d.location;
  if (camera_dir.filename().empty()) camera_dir = camera_dir.parent_path();  // trailing '/'
  return MakeSimulatedCamera(camera_dir, d.masks(), o);
}

}  // namespace silnet::node
