#include "aggregator/hulls/silhouette_source.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "shared/io/dataset_layout.h"
#include "shared/io/session_log.h"
#include "shared/io/session_log_reader.h"
#include "shared/silhouette/contour_codec.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

void CheckSize(const cv::Mat& mask, const CameraModel& camera, const std::string& where) {
  if (mask.cols != camera.width || mask.rows != camera.height) {
    throw InputError(fmt::format("{} is {}x{} but the calibration of {} says {}x{}", where,
                                 mask.cols, mask.rows, camera.id, camera.width, camera.height));
  }
}

// Mask images of a dataset folder.
class DatasetSilhouettes : public SilhouetteSource {
 public:
  explicit DatasetSilhouettes(const std::filesystem::path& root) : layout_(root) {}

  std::vector<std::string> CameraIds() const override { return layout_.CameraIds(); }
  int FrameCount(const std::string& camera) const override {
    return layout_.CountImages(camera, "masks");
  }
  cv::Mat Mask(const CameraModel& camera, int frame) const override {
    const std::string where = Where(camera.id, frame);
    cv::Mat mask = cv::imread(where, cv::IMREAD_GRAYSCALE);
    if (mask.empty()) throw InputError(fmt::format("cannot read mask {}", where));
    CheckSize(mask, camera, "mask " + where);
    return mask;
  }
  std::string Where(const std::string& camera, int frame) const override {
    return layout_.MaskPath(camera, frame).string();
  }
  const std::filesystem::path& root() const override { return layout_.root(); }

 private:
  DatasetLayout layout_;
};

// Contour records of a session store, each camera's newest session.
class SessionSilhouettes : public SilhouetteSource {
 public:
  explicit SessionSilhouettes(std::filesystem::path dir) : dir_(std::move(dir)) {
    for (const std::string& id : SessionLogCameras(dir_)) {
      SessionReadReport report;
      std::vector<SessionFrames> sessions = ReadSessionLog(SessionLogPath(dir_, id), &report);
      if (!report.problem.empty()) spdlog::warn("{}: {}", id, report.problem);
      if (sessions.empty() || sessions.back().contours.empty()) continue;
      Camera& camera = cameras_[id];
      camera.session = sessions.back().session;
      for (FrameRecord& record : sessions.back().contours)
        camera.contours.emplace(record.frame_index, std::move(record));
    }
  }

  std::vector<std::string> CameraIds() const override {
    std::vector<std::string> ids;
    for (const auto& [id, camera] : cameras_)
      ids.push_back(id);
    return ids;
  }
  int FrameCount(const std::string& camera) const override {
    auto it = cameras_.find(camera);
    if (it == cameras_.end() || it->second.contours.empty()) return 0;
    return static_cast<int>(it->second.contours.rbegin()->first + 1);
  }
  cv::Mat Mask(const CameraModel& camera, int frame) const override {
    auto it = cameras_.find(camera.id);
    const FrameRecord* record = nullptr;
    if (it != cameras_.end() && frame >= 0) {
      auto found = it->second.contours.find(static_cast<uint64_t>(frame));
      if (found != it->second.contours.end()) record = &found->second;
    }
    if (record == nullptr) {
      throw InputError(fmt::format(
          "{} has no contour (its node sends one every few frames: set contour_every 1 for "
          "hulls of every frame)",
          Where(camera.id, frame)));
    }
    return ContourRecordMask(*record, camera, Where(camera.id, frame));
  }
  std::string Where(const std::string& camera, int frame) const override {
    auto it = cameras_.find(camera);
    return fmt::format("{} frame {} of session {}", SessionLogPath(dir_, camera).string(), frame,
                       it == cameras_.end() ? 0u : it->second.session);
  }
  const std::filesystem::path& root() const override { return dir_; }

 private:
  struct Camera {
    uint32_t session = 0;
    std::map<uint64_t, FrameRecord> contours;
  };
  std::filesystem::path dir_;
  std::map<std::string, Camera> cameras_;
};

}  // namespace

std::unique_ptr<SilhouetteSource> OpenSilhouetteSource(const std::filesystem::path& input) {
  for (const std::filesystem::path& dir : {input, input / "sessions"}) {
    if (!SessionLogCameras(dir).empty()) return std::make_unique<SessionSilhouettes>(dir);
  }
  return std::make_unique<DatasetSilhouettes>(input);
}

cv::Mat ContourRecordMask(const FrameRecord& record, const CameraModel& camera,
                          const std::string& where) {
  SilhouetteContours contours;
  std::string error;
  if (!DecodeContours(record.payload, record.width, record.height, &contours, &error))
    throw InputError(fmt::format("{}: {}", where, error));
  cv::Mat mask = RasteriseContours(contours, record.width, record.height);
  CheckSize(mask, camera, where);
  return mask;
}

cv::Mat RasteriseContours(const SilhouetteContours& contours, int width, int height) {
  constexpr int kShift = 4;  // 1/16 px fixed point
  constexpr double kScale = 1 << kShift;
  cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
  cv::Mat polygon_mask(height, width, CV_8UC1);
  auto to_points = [&](const std::vector<Eigen::Vector2f>& ring) {
    std::vector<cv::Point> points;
    points.reserve(ring.size());
    for (const Eigen::Vector2f& p : ring) {
      points.emplace_back(static_cast<int>(std::lround(p.x() * kScale)),
                          static_cast<int>(std::lround(p.y() * kScale)));
    }
    return points;
  };
  for (const ContourPolygon& polygon : contours.polygons) {
    std::vector<std::vector<cv::Point>> rings{to_points(polygon.outer)};
    for (const auto& hole : polygon.holes)
      rings.push_back(to_points(hole));
    polygon_mask.setTo(0);
    cv::fillPoly(polygon_mask, rings, cv::Scalar(255), cv::LINE_8, kShift);
    mask |= polygon_mask;
  }
  return mask;
}

}  // namespace silnet::aggregator
