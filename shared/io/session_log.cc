#include "shared/io/session_log.h"

#include <algorithm>
#include <sstream>
#include <string_view>

#include "shared/util/parse_number.h"

namespace silnet {
namespace {

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

std::string Unescape(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size()) {
      out += text[i + 1] == 'n' ? '\n' : text[i + 1];
      ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

}  // namespace

std::filesystem::path SessionLogPath(const std::filesystem::path& dir,
                                     const std::string& camera_id) {
  return dir / (camera_id + kSessionLogExtension);
}

std::vector<std::string> SessionLogCameras(const std::filesystem::path& dir) {
  std::vector<std::string> ids;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(dir, error)) {
    if (entry.is_regular_file() && entry.path().extension() == kSessionLogExtension) {
      ids.push_back(entry.path().stem().string());
    }
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<uint8_t> SerializeCameraInfo(const CameraInfoRecord& info) {
  std::ostringstream out;
  out << "camera_id=" << Escape(info.camera_id) << "\n"
      << "session=" << info.session << "\n"
      << "host=" << Escape(info.host) << "\n"
      << "node_version=" << Escape(info.node_version) << "\n"
      << "source_kind=" << Escape(info.source_kind) << "\n"
      << "width=" << info.width << "\n"
      << "height=" << info.height << "\n"
      << "nominal_fps=" << info.nominal_fps << "\n"
      << "segmentation=" << Escape(info.segmentation) << "\n";
  for (const auto& [name, value] : info.parameters) {
    out << "parameter." << Escape(name) << "=" << Escape(value) << "\n";
  }
  const std::string text = out.str();
  return std::vector<uint8_t>(text.begin(), text.end());
}

bool ParseCameraInfo(std::span<const uint8_t> bytes, CameraInfoRecord* info, std::string* error) {
  CameraInfoRecord r;
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  std::string line;
  bool ok = true;
  while (ok && std::getline(in, line)) {
    const size_t eq = line.find('=');
    if (eq == std::string::npos) {
      ok = false;
      break;
    }
    const std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    if (key == "camera_id") {
      r.camera_id = Unescape(value);
    } else if (key == "session") {
      ok = ParseWholeNumber(value, &r.session);
    } else if (key == "host") {
      r.host = Unescape(value);
    } else if (key == "node_version") {
      r.node_version = Unescape(value);
    } else if (key == "source_kind") {
      r.source_kind = Unescape(value);
    } else if (key == "width") {
      ok = ParseWholeNumber(value, &r.width);
    } else if (key == "height") {
      ok = ParseWholeNumber(value, &r.height);
    } else if (key == "nominal_fps") {
      ok = ParseWholeNumber(value, &r.nominal_fps);
    } else if (key == "segmentation") {
      r.segmentation = Unescape(value);
    } else if (key.rfind("parameter.", 0) == 0) {
      r.parameters[Unescape(key.substr(10))] = Unescape(value);
    }
  }
  if (!ok || r.camera_id.empty()) {
    if (error != nullptr) *error = "malformed camera info record";
    return false;
  }
  *info = std::move(r);
  return true;
}

}  // namespace silnet
