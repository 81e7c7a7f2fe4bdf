// LibcameraSource cannot stream here (no cameras in containers, and libcamera 0.0.3 has no
// software camera); what is tested is that asking for a camera that does not exist fails
// cleanly with a readable CaptureError.

#ifdef SILNET_HAVE_LIBCAMERA

#include "node/capture/libcamera/libcamera_source.h"

#include <gtest/gtest.h>

#include <string>

namespace silnet::node {
namespace {

// Opens `options` expecting a CaptureError and returns its message.
std::string OpenError(const LibcameraSourceOptions& options) {
  LibcameraSource source(options);
  try {
    source.Open();
  } catch (const CaptureError& error) {
    source.Close();
    source.Close();
    return error.what();
  }
  ADD_FAILURE() << "Open() of a camera that does not exist did not throw";
  return "";
}

TEST(LibcameraSource, UnknownCameraIdThrowsListingTheCameras) {
  LibcameraSourceOptions options;
  options.camera_id = "silnet-test-no-such-camera";
  const std::string message = OpenError(options);
  EXPECT_NE(message.find("libcamera"), std::string::npos) << message;
  EXPECT_NE(message.find("silnet-test-no-such-camera"), std::string::npos) << message;
  EXPECT_NE(message.find("cameras: "), std::string::npos) << message;
}

TEST(LibcameraSource, CameraIndexPastTheListThrows) {
  LibcameraSourceOptions options;
  options.camera_index = 1000;
  const std::string message = OpenError(options);
  EXPECT_NE(message.find("camera index 1000"), std::string::npos) << message;
  EXPECT_NE(message.find("cameras: "), std::string::npos) << message;
}

TEST(LibcameraSource, DescribesTheRequestedCameraBeforeOpen) {
  LibcameraSourceOptions options;
  options.camera_id = "some-camera";
  const LibcameraSource source(options);
  EXPECT_EQ(source.Kind(), "libcamera");
  EXPECT_NE(source.Describe().find("libcamera:some-camera"), std::string::npos)
      << source.Describe();
}

}  // namespace
}  // namespace silnet::node

#endif  // SILNET_HAVE_LIBCAMERA
