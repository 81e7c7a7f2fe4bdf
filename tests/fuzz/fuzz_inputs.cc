#include "tests/fuzz/fuzz_inputs.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <opencv2/imgproc.hpp>

#include "shared/dds/sample_conversions.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/point_cloud_ply.h"
#include "shared/io/session_log.h"
#include "shared/io/session_log_reader.h"
#include "shared/record/record_log.h"
#include "shared/silhouette/contour_codec.h"
#include "shared/silhouette/frame_sample_check.h"
#include "shared/silhouette/hull_codec.h"
#include "shared/silhouette/silhouette_contour.h"
#include "shared/silhouette/silhouette_hull.h"
#include "shared/util/check.h"

namespace silnet::fuzz {
namespace {

constexpr size_t kCameraIdBytes = sizeof(silnet_wire_HullFrame{}.camera_id);
constexpr size_t kHeaderBytes = kCameraIdBytes + 4 + 8 + 8 + 2 + 2 + 4;
// The HullFrame payload is a bounded sequence: DDS refuses longer ones before we see them.
constexpr size_t kMaxHullPayload = 2048;

// Stops the fuzzer with a message when an invariant does not hold.
void Require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
    std::abort();
  }
}

// Writes `bytes` to this process's scratch file named `name` and returns its path.
std::filesystem::path WriteScratch(const std::string& name, std::span<const uint8_t> bytes) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("silnet-fuzz-" + std::to_string(::getpid()) + "-" + name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  return path;
}

// The bytes of the file at `path`, which is then removed.
std::vector<uint8_t> TakeFile(const std::filesystem::path& path) {
  std::vector<uint8_t> bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::filesystem::remove(path);
  return bytes;
}

template <class T>
void Put(std::vector<uint8_t>* out, T value) {
  const size_t at = out->size();
  out->resize(at + sizeof(T));
  std::memcpy(out->data() + at, &value, sizeof(T));
}

template <class T>
T Get(std::span<const uint8_t> bytes, size_t* offset) {
  T value{};
  std::memcpy(&value, bytes.data() + *offset, sizeof(T));
  *offset += sizeof(T);
  return value;
}

// Fills the header fields shared by HullFrame and Contour from the packed bytes.
template <class Sample>
void UnpackHeader(std::span<const uint8_t> bytes, Sample* sample) {
  size_t offset = 0;
  std::memcpy(sample->camera_id, bytes.data(), kCameraIdBytes);
  offset += kCameraIdBytes;
  sample->session = Get<uint32_t>(bytes, &offset);
  sample->frame_index = Get<uint64_t>(bytes, &offset);
  sample->capture_time_ns = Get<int64_t>(bytes, &offset);
  sample->image_width = Get<uint16_t>(bytes, &offset);
  sample->image_height = Get<uint16_t>(bytes, &offset);
  sample->flags = Get<uint32_t>(bytes, &offset);
}

void CheckDecodedHull(const FrameRecord& record) {
  HullPayload payload;
  std::string error;
  Require(DecodeHull(record.payload, record.width, record.height, &payload, &error),
          "a hull that passed the sample check decodes");
  const SilhouetteHull& hull = payload.hull;
  Require(hull.size() <= kMaxHullVertices, "hull vertex count bounded");
  Require(hull.clipped().size() == hull.vertices().size(), "one clipped bit per edge");
  Require(hull.edge_angles().size() == hull.vertices().size(), "one tangent per edge");
  for (const Eigen::Vector2d& v : hull.vertices()) {
    Require(v.x() >= -0.5 && v.x() <= record.width - 0.5 && v.y() >= -0.5 &&
                v.y() <= record.height - 0.5,
            "hull vertices inside the image");
  }
  if (hull.size() >= 3) Require(hull.Area() > 0.0, "hull in positive orientation");
  Require(payload.foreground_pixels >= 0, "foreground pixel count not negative");
  // What decodes re-encodes to a payload that decodes to the same hull.
  HullPayload again;
  Require(DecodeHull(EncodeHull(payload), record.width, record.height, &again, &error),
          "a decoded hull re-encodes to a valid payload");
  Require(again.hull.vertices() == hull.vertices(), "re-encoding keeps the vertices");
}

void CheckDecodedContours(const FrameRecord& record) {
  SilhouetteContours contours;
  std::string error;
  Require(DecodeContours(record.payload, record.width, record.height, &contours, &error),
          "contours that passed the sample check decode");
  for (const ContourPolygon& polygon : contours.polygons) {
    Require(polygon.outer.size() >= 3, "rings have at least three points");
    for (const auto& hole : polygon.holes)
      Require(hole.size() >= 3, "holes have at least three points");
  }
  Require(std::isfinite(contours.Area()), "contour area finite");
}

}  // namespace

std::vector<uint8_t> PackFrameSample(const FrameRecord& record) {
  std::vector<uint8_t> out(kCameraIdBytes, 0);
  std::memcpy(out.data(), record.camera_id.data(),
              std::min(record.camera_id.size(), kCameraIdBytes - 1));
  Put(&out, record.session);
  Put(&out, record.frame_index);
  Put(&out, record.capture_time_ns);
  Put(&out, record.width);
  Put(&out, record.height);
  Put(&out, record.flags);
  out.insert(out.end(), record.payload.begin(), record.payload.end());
  return out;
}

int FuzzFrameSample(std::span<const uint8_t> bytes) {
  if (bytes.size() < kHeaderBytes) return 0;
  int accepted = 0;
  std::vector<uint8_t> payload(bytes.begin() + kHeaderBytes, bytes.end());

  silnet_wire_HullFrame hull_sample{};
  UnpackHeader(bytes, &hull_sample);
  hull_sample.hull._buffer = payload.data();
  hull_sample.hull._length = static_cast<uint32_t>(std::min(payload.size(), kMaxHullPayload));
  hull_sample.hull._maximum = hull_sample.hull._length;
  const FrameRecord hull_record = dds::FromWire(hull_sample);
  if (FindFrameSampleProblem(hull_record, FramePayloadKind::kHull).empty()) {
    CheckDecodedHull(hull_record);
    ++accepted;
  }

  silnet_wire_Contour contour_sample{};
  UnpackHeader(bytes, &contour_sample);
  contour_sample.polygons._buffer = payload.data();
  contour_sample.polygons._length = static_cast<uint32_t>(payload.size());
  contour_sample.polygons._maximum = contour_sample.polygons._length;
  const FrameRecord contour_record = dds::FromWire(contour_sample);
  if (FindFrameSampleProblem(contour_record, FramePayloadKind::kContour).empty()) {
    CheckDecodedContours(contour_record);
    ++accepted;
  }
  return accepted;
}

int FuzzSessionLog(std::span<const uint8_t> bytes) {
  const std::filesystem::path path =
      WriteScratch(std::string("session") + kSessionLogExtension, bytes);
  SessionReadReport report;
  std::vector<SessionFrames> sessions;
  try {
    sessions = ReadSessionLog(path, &report);
  } catch (const InputError&) {
    return 0;  // not a session log: refused with a reason, as promised
  }
  uint64_t frames = 0;
  for (size_t i = 0; i < sessions.size(); ++i) {
    if (i > 0) Require(sessions[i - 1].session < sessions[i].session, "sessions ascending");
    for (const auto* list : {&sessions[i].hulls, &sessions[i].contours}) {
      for (size_t j = 0; j < list->size(); ++j) {
        Require((*list)[j].session == sessions[i].session, "frames filed under their session");
        if (j > 0) {
          Require((*list)[j - 1].frame_index < (*list)[j].frame_index,
                  "frame indices strictly increasing");
        }
      }
      frames += list->size();
    }
  }
  Require(frames + report.duplicates + report.malformed <= report.records,
          "every frame, duplicate and malformed record was a record read");
  return static_cast<int>(frames);
}

int FuzzInputFile(std::span<const uint8_t> bytes) {
  if (bytes.empty()) return 0;
  const bool yaml = bytes[0] % 2 == 0;
  const std::filesystem::path path =
      WriteScratch(yaml ? "input.yaml" : "input.ply", bytes.subspan(1));
  try {
    if (!yaml) {
      const OrientedPointCloud cloud = ReadPointCloudPly(path);
      Require(cloud.points.size() == cloud.normals.size(), "one normal per point");
      return 1;
    }
    const std::vector<CameraModel> cameras = LoadCamerasAtFrame(path, 1000);
    for (size_t i = 0; i < cameras.size(); ++i) {
      const CameraModel& c = cameras[i];
      Require(!c.id.empty() && c.width > 0 && c.height > 0, "an id and a positive size");
      Require(c.K(0, 0) > 0 && c.K(1, 1) > 0 && c.K(2, 2) == 1, "positive focal lengths");
      Require(c.K.allFinite() && c.R.allFinite() && c.t.allFinite() && c.dist.allFinite(),
              "finite matrices");
      Require((c.R * c.R.transpose() - Eigen::Matrix3d::Identity()).norm() <= 1e-6 &&
                  c.R.determinant() > 0,
              "R a rotation");
      Require(std::isfinite(c.fps) && c.fps > 0 && std::isfinite(c.time_offset),
              "finite positive fps and a finite offset");
      for (size_t j = 0; j < i; ++j)
        Require(cameras[j].id != c.id, "distinct camera ids");
    }
    return 1;
  } catch (const InputError&) {
    return 0;  // refused with a reason, as promised
  }
}

std::vector<std::vector<uint8_t>> FrameSampleSeeds() {
  std::vector<std::vector<uint8_t>> seeds;
  const cv::Size size(160, 120);
  std::vector<cv::Mat> masks;
  cv::Mat ellipse = cv::Mat::zeros(size, CV_8UC1);
  cv::ellipse(ellipse, {80, 60}, {40, 25}, 30, 0, 360, 255, cv::FILLED);
  masks.push_back(ellipse);
  cv::Mat ring = cv::Mat::zeros(size, CV_8UC1);
  cv::circle(ring, {60, 60}, 40, 255, cv::FILLED);
  cv::circle(ring, {60, 60}, 15, 0, cv::FILLED);
  cv::rectangle(ring, {120, 10}, {159, 50}, 255, cv::FILLED);  // touches the border
  masks.push_back(ring);
  masks.push_back(cv::Mat::zeros(size, CV_8UC1));  // an empty frame
  uint64_t index = 0;
  for (const cv::Mat& mask : masks) {
    FrameRecord record;
    record.camera_id = "cam00";
    record.session = 2;
    record.frame_index = index++;
    record.capture_time_ns = 1'000'000'000LL * static_cast<int64_t>(index);
    record.width = static_cast<uint16_t>(size.width);
    record.height = static_cast<uint16_t>(size.height);
    MaskSummary summary;
    HullPayload payload{ComputeSilhouetteHull(mask, &summary), summary.foreground_pixels};
    record.payload = EncodeHull(payload);
    seeds.push_back(PackFrameSample(record));
    record.payload = EncodeContours(ExtractContours(mask));
    seeds.push_back(PackFrameSample(record));
  }
  return seeds;
}

std::vector<std::vector<uint8_t>> SessionLogSeeds() {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("silnet-fuzz-seed-" + std::to_string(::getpid()) + kSessionLogExtension);
  std::filesystem::remove(path);
  {
    RecordLogWriter writer;
    Require(writer.Open(path, kSessionLogStreamKind).ok(), "seed log opens");
    CameraInfoRecord info;
    info.camera_id = "cam00";
    info.width = 160;
    info.height = 120;
    Require(writer
                .Append(static_cast<uint16_t>(SessionRecordType::kCameraInfo),
                        SerializeCameraInfo(info))
                .ok(),
            "seed info appended");
    const auto samples = FrameSampleSeeds();
    auto append_hull = [&](uint32_t session, uint64_t index, const std::vector<uint8_t>& sample) {
      FrameRecord record;
      record.camera_id = "cam00";
      record.session = session;
      record.frame_index = index;
      record.width = 160;
      record.height = 120;
      record.payload.assign(sample.begin() + kHeaderBytes, sample.end());
      Require(writer
                  .Append(static_cast<uint16_t>(SessionRecordType::kHullFrame),
                          SerializeFrameRecord(record))
                  .ok(),
              "seed frame appended");
    };
    for (uint32_t session : {1u, 2u}) {
      for (uint64_t i = 0; i < 3; ++i)
        append_hull(session, 2 - i, samples[2 * i]);  // out of order: the reader sorts
    }
    append_hull(2, 0, samples[4]);  // a duplicate, last: the torn tail cuts it
  }
  const std::vector<uint8_t> log = TakeFile(path);
  std::vector<std::vector<uint8_t>> seeds{log};
  seeds.emplace_back(log.begin(), log.end() - 7);  // a torn tail
  return seeds;
}

std::vector<std::vector<uint8_t>> InputFileSeeds() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string stem = "silnet-fuzz-seed-" + std::to_string(::getpid());
  std::vector<CameraModel> cameras(2);
  for (size_t i = 0; i < cameras.size(); ++i) {
    CameraModel& c = cameras[i];
    c.id = "cam0" + std::to_string(i);
    c.width = 640;
    c.height = 480;
    c.K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
    c.dist << -0.1, 0.01, 0, 0, 0;
    c.R = Eigen::AngleAxisd(0.5 * static_cast<double>(i), Eigen::Vector3d::UnitY()).matrix();
    c.t = Eigen::Vector3d(0.1, 0, 4);
    c.time_offset = 2.5;
  }
  CameraMoveRecord move{120, cameras[1]};
  move.camera.t.x() += 0.3;
  const std::filesystem::path yaml = dir / (stem + ".yaml");
  {
    cv::FileStorage storage(yaml.string(), cv::FileStorage::WRITE);
    WriteCameras(storage, cameras);
    WriteCameraMoves(storage, {move});
  }
  OrientedPointCloud cloud;
  cloud.comments = {"a seed"};
  for (int k = 0; k < 4; ++k) {
    cloud.points.emplace_back(0.1f * static_cast<float>(k), 0, 1);
    cloud.normals.emplace_back(0, 0, 1);
  }
  const std::filesystem::path ply = dir / (stem + ".ply");
  WritePointCloudPly(ply, cloud);
  std::vector<std::vector<uint8_t>> seeds;
  for (const auto& [selector, path] : {std::pair{uint8_t{0}, yaml}, std::pair{uint8_t{1}, ply}}) {
    std::vector<uint8_t> seed{selector};
    const std::vector<uint8_t> bytes = TakeFile(path);
    seed.insert(seed.end(), bytes.begin(), bytes.end());
    seeds.push_back(std::move(seed));
  }
  return seeds;
}

}  // namespace silnet::fuzz
