#include "shared/io/png_writer.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

TEST(PngWriter, ColourAndGreyImagesDecodeExactly) {
  testing::TempDir dir;
  cv::Mat colour(37, 53, CV_8UC3), grey(37, 53, CV_8U);
  cv::randu(colour, 0, 256);
  cv::randu(grey, 0, 256);
  WritePngFast(dir / "c.png", colour);
  WritePngFast(dir / "g.png", grey);
  const cv::Mat c = cv::imread((dir / "c.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat g = cv::imread((dir / "g.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(c.type(), CV_8UC3);
  ASSERT_EQ(g.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(c, colour, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(g, grey, cv::NORM_INF), 0.0);
}

TEST(PngWriter, RejectsUnsupportedTypesAndUnwritablePaths) {
  cv::Mat floats(4, 4, CV_32F, cv::Scalar(0));
  EXPECT_THROW(EncodePngFast(floats), CheckError);
  cv::Mat grey(4, 4, CV_8U, cv::Scalar(0));
  EXPECT_THROW(WritePngFast("/nonexistent-dir/x.png", grey), InputError);
}

}  // namespace
}  // namespace silnet
