#include "node/capture/files/image_folder_source.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string_view>
#include <system_error>
#include <utility>

#include "shared/util/check.h"

namespace silnet::node {
namespace {

constexpr std::string_view kImageExtensions[] = {".png", ".jpg", ".jpeg", ".bmp", ".pbm",
                                                 ".pgm", ".ppm", ".tif",  ".tiff"};

bool IsImageFile(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return std::find(std::begin(kImageExtensions), std::end(kImageExtensions), extension) !=
         std::end(kImageExtensions);
}

std::string FpsText(double fps) {
  return fps > 0.0 ? fmt::format("{:g} fps", fps) : "fps unknown";
}

}  // namespace

ImageFolderSource::ImageFolderSource(ImageFolderSourceOptions options)
    : options_(std::move(options)) {}

void ImageFolderSource::Open() {
  Close();
  const std::filesystem::path& folder = options_.folder;
  CheckReplayOptions(options_, "image folder " + folder.string());
  if (options_.real_time && options_.fps <= 0.0)
    throw CaptureError(
        fmt::format("image folder {}: real-time replay needs a frame rate", folder.string()));

  std::error_code error;
  if (!std::filesystem::is_directory(folder, error))
    throw CaptureError(
        fmt::format("image folder {} does not exist or is not a folder", folder.string()));
  std::vector<std::filesystem::path> all;
  for (std::filesystem::directory_iterator it(folder, error), end; !error && it != end;
       it.increment(error)) {
    std::error_code type_error;
    if (it->is_regular_file(type_error) && IsImageFile(it->path())) all.push_back(it->path());
  }
  if (error)
    throw CaptureError(
        fmt::format("cannot list image folder {}: {}", folder.string(), error.message()));
  if (all.empty())
    throw CaptureError(
        fmt::format("image folder {} holds no images (png, jpg, jpeg, bmp, pbm, "
                    "pgm, ppm, tif, tiff)",
                    folder.string()));
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return a.filename().string() < b.filename().string();
  });
  if (options_.first_frame >= all.size())
    throw CaptureError(
        fmt::format("image folder {} holds {} images; first frame {} is past the end",
                    folder.string(), all.size(), options_.first_frame));
  uint64_t count = all.size() - options_.first_frame;
  if (options_.max_frames > 0) count = std::min(count, options_.max_frames);
  const auto begin = all.begin() + static_cast<std::ptrdiff_t>(options_.first_frame);
  files_.assign(begin, begin + static_cast<std::ptrdiff_t>(count));

  format_ = CaptureFormat{};
  format_.width = options_.width;
  format_.height = options_.height;
  format_.fps = options_.fps;
  format_.pixel_format = options_.masks ? "GRAY" : "BGR";
  if (format_.width == 0) {
    // The first readable image sets the size; the first image is kept to save a decode.
    for (size_t position = 0; position < files_.size(); ++position) {
      cv::Mat image = Decode(position);
      if (image.empty()) continue;
      format_.width = image.cols;
      format_.height = image.rows;
      if (position == 0) pending_ = Make(0, std::move(image));
      break;
    }
    if (pending_) next_ = 1;
  }

  if (options_.fps > 0.0) {
    const int64_t start = options_.start_ns != 0 ? options_.start_ns : RealtimeNowNs();
    pacer_.emplace(options_.fps, start, options_.offset_frames);
  }
  open_ = true;
}

cv::Mat ImageFolderSource::Decode(size_t position) const {
  try {
    return cv::imread(files_[position].string(),
                      options_.masks ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

ReplayedFrame ImageFolderSource::Make(size_t position, cv::Mat image) const {
  ReplayedFrame pending;
  pending.position = position;
  const std::string name = files_[position].string();
  if (image.empty()) {
    pending.error = fmt::format("cannot read image {} (missing, corrupt or not an image)", name);
  } else if (image.cols != format_.width || image.rows != format_.height) {
    pending.error = fmt::format("image {} is {}x{}, expected {}x{}", name, image.cols, image.rows,
                                format_.width, format_.height);
  } else {
    SILNET_CHECK(image.type() == (options_.masks ? CV_8UC1 : CV_8UC3));
    pending.image = std::move(image);
  }
  return pending;
}

CaptureStatus ImageFolderSource::Read(CapturedFrame* frame, std::chrono::milliseconds timeout) {
  SILNET_CHECK_MSG(open_, "ImageFolderSource::Read() before Open()");
  SILNET_CHECK(frame != nullptr);
  if (!pending_) {
    if (next_ >= files_.size()) return CaptureStatus::kEndOfStream;
    pending_ = Make(next_, Decode(next_));
    ++next_;
  }
  return DeliverReplayedFrame(&pending_, pacer_, options_.real_time, options_.first_frame, timeout,
                              frame, &counters_, &last_error_);
}

void ImageFolderSource::Close() {
  open_ = false;
  files_.clear();
  next_ = 0;
  pending_.reset();
  pacer_.reset();
}

std::string ImageFolderSource::Describe() const {
  return fmt::format("images:{} {}x{} {} {}, {} images", options_.folder.string(), format_.width,
                     format_.height, format_.pixel_format, FpsText(format_.fps), files_.size());
}

}  // namespace silnet::node
