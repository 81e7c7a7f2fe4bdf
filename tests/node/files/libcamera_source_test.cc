// LibcameraSource cannot stream here (no cameras in containers, and libcamera 0.0.3 has no
// software camera); what is tested is that asking for a camera that does not exist fails
// cleanly with a readable CaptureError.

#ifdef SILNET_HAVE_LIBCAMERA

#include "node/capture/libcamera/libcamera_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace silnet::node {
namespace {

TEST(LibcameraSource, UnknownCameraIdThrowsListingTheCameras) {
  LibcameraSourceOptions options;
  options.camera_id = "silnet-test-no-such-camera";
  LibcameraSource source(options);
  EXPECT_THAT([&] { source.Open(); }, ::testing::ThrowsMessage<CaptureError>(::testing::AllOf(
                                          ::testing::HasSubstr("libcamera"),
                                          ::testing::HasSubstr("silnet-test-no-such-camera"),
                                          ::testing::HasSubstr("cameras: "))));
  // Closing after the failed Open(), even twice, is safe.
  source.Close();
  source.Close();
}

TEST(LibcameraSource, CameraIndexPastTheListThrows) {
  LibcameraSourceOptions options;
  options.camera_index = 1000;
  LibcameraSource source(options);
  EXPECT_THAT([&] { source.Open(); },
              ::testing::ThrowsMessage<CaptureError>(::testing::AllOf(
                  ::testing::HasSubstr("camera index 1000"), ::testing::HasSubstr("cameras: "))));
  source.Close();
  source.Close();
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
