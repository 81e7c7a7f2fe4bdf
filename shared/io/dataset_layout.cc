#include "shared/io/dataset_layout.h"

#include <fmt/format.h>

#include <algorithm>

namespace silnet {

std::filesystem::path DatasetLayout::FramesDir(const std::string& camera_id) const {
  return CameraDir(camera_id) / "frames";
}

std::filesystem::path DatasetLayout::MasksDir(const std::string& camera_id) const {
  return CameraDir(camera_id) / "masks";
}

std::filesystem::path DatasetLayout::FramePath(const std::string& camera_id, int frame) const {
  return FramesDir(camera_id) / ImageName(frame);
}

std::filesystem::path DatasetLayout::MaskPath(const std::string& camera_id, int frame) const {
  return MasksDir(camera_id) / ImageName(frame);
}

std::string DatasetLayout::ImageName(int frame) {
  return fmt::format("{:06d}.png", frame);
}

std::vector<std::string> DatasetLayout::CameraIds() const {
  std::vector<std::string> ids;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(root_, error)) {
    if (!entry.is_directory()) continue;
    const std::string id = entry.path().filename().string();
    if (std::filesystem::is_directory(FramesDir(id)) ||
        std::filesystem::is_directory(MasksDir(id))) {
      ids.push_back(id);
    }
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<std::string> DatasetLayout::CameraIdsWithFile(const std::string& file_name) const {
  std::vector<std::string> ids;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(root_, error)) {
    if (entry.is_directory() && std::filesystem::is_regular_file(entry.path() / file_name))
      ids.push_back(entry.path().filename().string());
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

int DatasetLayout::CountImages(const std::string& camera_id, const std::string& kind) const {
  const std::filesystem::path dir = CameraDir(camera_id) / kind;
  int count = 0;
  while (std::filesystem::exists(dir / ImageName(count)))
    ++count;
  return count;
}

}  // namespace silnet
