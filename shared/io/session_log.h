#pragma once
// Session logs: the per-camera record logs (shared/record/record_log.h) in which the node
// (--record) and the aggregator (its session store) keep a camera's streams.
//   <dir>/<camera-id>.silnetlog, stream kind "silnet-frames-v1", records:
//     kHullFrame  a serialised FrameRecord with a hull payload
//     kContour    a serialised FrameRecord with a contour payload
//     kCameraInfo a serialised CameraInfoRecord

#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace silnet {

inline constexpr const char* kSessionLogStreamKind = "silnet-frames-v1";
inline constexpr const char* kSessionLogExtension = ".silnetlog";

// Record types of a session log.
enum class SessionRecordType : uint16_t { kHullFrame = 1, kContour = 2, kCameraInfo = 3 };

// The session log of a camera in `dir`.
std::filesystem::path SessionLogPath(const std::filesystem::path& dir,
                                     const std::string& camera_id);

// The camera ids with a session log in `dir`, sorted.
std::vector<std::string> SessionLogCameras(const std::filesystem::path& dir);

// What a node says about its camera (the CameraInfo sample), independent of DDS.
struct CameraInfoRecord {
  std::string camera_id;
  uint32_t session = 0;
  std::string host;
  std::string node_version;
  std::string source_kind;
  uint16_t width = 0;
  uint16_t height = 0;
  double nominal_fps = 0.0;
  std::string segmentation;
  std::map<std::string, std::string> parameters;

  bool operator==(const CameraInfoRecord&) const = default;
};

// Serialises a CameraInfoRecord (text lines "key=value", values escaped).
std::vector<uint8_t> SerializeCameraInfo(const CameraInfoRecord& info);
// Parses SerializeCameraInfo's output; false with a reason on malformed input.
bool ParseCameraInfo(std::span<const uint8_t> bytes, CameraInfoRecord* info, std::string* error);

}  // namespace silnet
