#include "sim/ground_truth.h"

#include <cmath>
#include <opencv2/core/eigen.hpp>
#include <opencv2/core/persistence.hpp>

#include "shared/geometry/epipolar.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"

namespace silnet::sim {
namespace {

constexpr int kColumns = 26;

cv::Mat EncodePrimitiveRows(const std::vector<Primitive>& primitives) {
  cv::Mat rows(static_cast<int>(primitives.size()), kColumns, CV_64F, cv::Scalar(0));
  for (int i = 0; i < rows.rows; ++i) {
    const Primitive& p = primitives[static_cast<size_t>(i)];
    double* r = rows.ptr<double>(i);
    r[0] = p.kind == PrimitiveKind::kCapsule ? 0 : 1;
    r[1] = p.subject;
    r[2] = p.part;
    for (int k = 0; k < 3; ++k) {
      r[3 + k] = p.a[k];
      r[6 + k] = p.b[k];
      r[10 + k] = p.center[k];
      r[13 + k] = p.radii[k];
      for (int c = 0; c < 3; ++c)
        r[16 + 3 * k + c] = p.axes(k, c);
    }
    r[9] = p.radius;
  }
  return rows;
}

cv::Mat ToMat(const Eigen::Matrix3d& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

}  // namespace

std::vector<Primitive> DecodePrimitiveRows(const cv::Mat& rows) {
  if (rows.cols != kColumns || rows.type() != CV_64F) {
    throw InputError("subject frame matrix must be N x 26 doubles");
  }
  std::vector<Primitive> out;
  for (int i = 0; i < rows.rows; ++i) {
    const double* r = rows.ptr<double>(i);
    Primitive p;
    p.kind = r[0] == 0 ? PrimitiveKind::kCapsule : PrimitiveKind::kEllipsoid;
    p.subject = static_cast<int>(r[1]);
    p.part = static_cast<int>(r[2]);
    for (int k = 0; k < 3; ++k) {
      p.a[k] = r[3 + k];
      p.b[k] = r[6 + k];
      p.center[k] = r[10 + k];
      p.radii[k] = r[13 + k];
      for (int c = 0; c < 3; ++c)
        p.axes(k, c) = r[16 + 3 * k + c];
    }
    p.radius = r[9];
    out.push_back(p);
  }
  return out;
}

std::pair<int, int> ReferenceFrameRange(const std::vector<CameraModel>& cameras, int frames,
                                        double reference_fps) {
  double begin = std::numeric_limits<double>::infinity(), end = -begin;
  for (const CameraModel& c : cameras) {
    begin = std::min(begin, c.ExposureTime(0));
    end = std::max(end, c.ExposureTime(frames - 1));
  }
  const int first = static_cast<int>(std::floor(begin * reference_fps));
  const int last = static_cast<int>(std::ceil(end * reference_fps));
  return {first, last - first + 1};
}

void WriteGroundTruth(const std::filesystem::path& path, const GroundTruthScene& summary,
                      const std::vector<CameraModel>& cameras, const Scene& scene,
                      const std::vector<CameraMoveRecord>& moves) {
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw InputError(path.string() + ": cannot write");
  fs << "silnet_ground_truth_version" << 1;
  fs << "scene"
     << "{";
  fs << "subject" << summary.subject << "subjects" << summary.subjects << "layout" << summary.layout
     << "seed" << std::to_string(summary.seed) << "reference_fps" << summary.reference_fps
     << "frames" << summary.frames;
  fs << "}";
  WriteCameras(fs, cameras);
  if (!moves.empty()) WriteCameraMoves(fs, moves);
  fs << "pairs"
     << "[";
  for (size_t i = 0; i < cameras.size(); ++i) {
    for (size_t j = i + 1; j < cameras.size(); ++j) {
      const PairTiming timing = PairTimingFromCameras(cameras[i], cameras[j]);
      fs << "{"
         << "i" << cameras[i].id << "j" << cameras[j].id << "F"
         << ToMat(FundamentalFromCameras(cameras[i], cameras[j])) << "offset" << timing.offset
         << "rate" << timing.rate << "}";
    }
  }
  fs << "]";
  fs << "part_names"
     << "[";
  for (int s = 0; s < scene.subject_count(); ++s) {
    for (const std::string& part : scene.subject(s).PartNames()) {
      fs << std::to_string(s) + "/" + part;
    }
  }
  fs << "]";
  const auto [first, count] = ReferenceFrameRange(cameras, summary.frames, summary.reference_fps);
  fs << "subject_frames"
     << "{"
     << "first" << first << "count" << count << "geometry"
     << "[";
  for (int r = first; r < first + count; ++r) {
    fs << EncodePrimitiveRows(scene.PrimitivesAt(r / summary.reference_fps));
  }
  fs << "]"
     << "}";
}

}  // namespace silnet::sim
