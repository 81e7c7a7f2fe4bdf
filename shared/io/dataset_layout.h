#pragma once
// The dataset folder every offline job reads and silnet-sim writes (DESIGN.md "Files"):
//   <root>/<camera-id>/frames/%06d.png   colour frames
//   <root>/<camera-id>/masks/%06d.png    silhouettes (0 background, 255 foreground)
//   <root>/<camera-id>/<name>            silhouettes as one video file (a real capture's
//                                        segmentation output, e.g. MJPG masks)
//   <root>/ground_truth.yaml             simulated data only

#include <filesystem>
#include <string>
#include <vector>

namespace silnet {

// Paths inside one dataset folder.
class DatasetLayout {
 public:
  explicit DatasetLayout(std::filesystem::path root) : root_(std::move(root)) {}

  const std::filesystem::path& root() const { return root_; }
  std::filesystem::path CameraDir(const std::string& camera_id) const { return root_ / camera_id; }
  std::filesystem::path FramesDir(const std::string& camera_id) const;
  std::filesystem::path MasksDir(const std::string& camera_id) const;
  std::filesystem::path FramePath(const std::string& camera_id, int frame) const;
  std::filesystem::path MaskPath(const std::string& camera_id, int frame) const;
  std::filesystem::path GroundTruthPath() const { return root_ / "ground_truth.yaml"; }

  // Sorted ids of the camera folders (sub-folders holding frames/ or masks/).
  std::vector<std::string> CameraIds() const;
  // Sorted ids of the camera folders that hold a file named `file_name` (a mask video).
  std::vector<std::string> CameraIdsWithFile(const std::string& file_name) const;
  // Number of consecutive images 000000.png, 000001.png, ... in a camera's folder `kind`
  // ("frames" or "masks").
  int CountImages(const std::string& camera_id, const std::string& kind) const;

  // File name of frame `frame` ("000042.png").
  static std::string ImageName(int frame);

 private:
  std::filesystem::path root_;
};

}  // namespace silnet
