// The node's stills (node/publish/still_store.h): requests are due at their frame or later,
// once; the last few stills are held for re-sends; photos are encoded losslessly (PNG) or,
// above the size limit, as JPEG, and silhouettes as 0/255 PNG.

#include "node/publish/still_store.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "node/segmentation/weak_silhouette.h"
#include "shared/util/check.h"

namespace silnet::node {
namespace {

TEST(StillRequests, ARequestIsDueAtItsFrameOrLaterAndOnlyOnce) {
  StillRequests requests;
  requests.Add(1, 100);
  requests.Add(2, 0);
  requests.Add(3, 105);
  requests.Add(1, 50);  // the same still asked again: the first request stands
  EXPECT_EQ(requests.waiting(), 3u);
  EXPECT_EQ(requests.TakeDue(99), std::vector<uint64_t>{2});
  EXPECT_EQ(requests.TakeDue(101), std::vector<uint64_t>{1});
  EXPECT_TRUE(requests.TakeDue(102).empty());
  EXPECT_EQ(requests.TakeDue(200), std::vector<uint64_t>{3});
  EXPECT_EQ(requests.waiting(), 0u);
}

TEST(StillStore, HoldsTheLastStillsById) {
  StillStore store(2);
  for (uint64_t id : {10, 11, 12}) {
    EncodedStill still;
    still.still_id = id;
    still.frame_index = id * 2;
    store.Add(still);
  }
  EXPECT_FALSE(store.Find(10));
  ASSERT_TRUE(store.Find(12));
  EXPECT_EQ(store.Find(12)->frame_index, 24u);
  EXPECT_TRUE(store.Find(11));
}

TEST(EncodeStill, PhotosArePngOrAboveTheLimitJpegAndSilhouettesZeroOr255) {
  cv::Mat photo(48, 64, CV_8UC3);
  cv::randu(photo, 0, 255);
  cv::Mat mask = cv::Mat::zeros(48, 64, CV_8UC1);
  cv::circle(mask, {32, 24}, 12, 1, -1);  // any non-zero value is silhouette
  const EncodedStill png = EncodeStill(5, 17, 0, 123, photo, mask);
  EXPECT_EQ(png.photo_encoding, "png");
  EXPECT_EQ(png.frame_index, 17u);
  EXPECT_EQ(png.width, 64);
  EXPECT_EQ(cv::norm(cv::imdecode(png.photo, cv::IMREAD_COLOR), photo, cv::NORM_INF), 0.0);
  const cv::Mat decoded_mask = cv::imdecode(png.silhouette, cv::IMREAD_GRAYSCALE);
  cv::Mat expected;
  cv::compare(mask, 0, expected, cv::CMP_NE);
  EXPECT_EQ(cv::norm(decoded_mask, expected, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(decoded_mask == 255), cv::countNonZero(mask));
  // Weak evidence (weak_silhouette.h) keeps its value.
  cv::Mat with_weak = mask.clone();
  with_weak(cv::Rect(0, 0, 5, 5)).setTo(kWeakSilhouette);
  const cv::Mat weak_decoded =
      cv::imdecode(EncodeStill(7, 17, 0, 123, photo, with_weak).silhouette, cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::countNonZero(weak_decoded == kWeakSilhouette), 25);
  EXPECT_EQ(cv::countNonZero(weak_decoded == 255), cv::countNonZero(mask));

  const EncodedStill jpeg = EncodeStill(6, 18, 0, 124, photo, mask, 1000);
  EXPECT_EQ(jpeg.photo_encoding, "jpeg");
  const cv::Mat decoded = cv::imdecode(jpeg.photo, cv::IMREAD_COLOR);
  ASSERT_EQ(decoded.size(), photo.size());

  EXPECT_THROW(EncodeStill(7, 0, 0, 0, photo, cv::Mat::zeros(10, 10, CV_8UC1)), InputError);
  EXPECT_THROW(EncodeStill(7, 0, 0, 0, cv::Mat(), mask), InputError);
}

}  // namespace
}  // namespace silnet::node
