#include "shared/silhouette/hull_codec.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "tests/shared/silhouette_test_util.h"

namespace silnet {
namespace {

// A convex polygon with exactly `k` vertices on half-pixel positions.
SilhouetteHull PolygonHull(int k) {
  std::vector<Eigen::Vector2d> vertices;
  for (int i = 0; i < k; ++i) {
    const double a = 2.0 * std::numbers::pi * i / k;
    vertices.emplace_back(std::round(2 * (320 + 200 * std::cos(a))) / 2,
                          std::round(2 * (240 + 200 * std::sin(a))) / 2);
  }
  return SilhouetteHull(vertices, std::vector<bool>(vertices.size(), false));
}

TEST(HullCodec, RoundTripsExactly) {
  std::mt19937_64 rng(10);
  for (int trial = 0; trial < 200; ++trial) {
    HullPayload payload;
    const cv::Mat mask = testing::RandomBlobMask(rng, 640, 480, 1 + trial % 3, trial % 2 == 0);
    MaskSummary summary;
    payload.hull = ComputeSilhouetteHull(mask, &summary);
    payload.foreground_pixels = summary.foreground_pixels;
    const std::vector<uint8_t> bytes = EncodeHull(payload);
    HullPayload decoded;
    std::string error;
    ASSERT_TRUE(DecodeHull(bytes, 640, 480, &decoded, &error)) << error << " trial " << trial;
    ASSERT_EQ(decoded.hull.size(), payload.hull.size());
    for (int i = 0; i < payload.hull.size(); ++i) {
      EXPECT_EQ(decoded.hull.vertex(i), payload.hull.vertex(i));
      EXPECT_EQ(decoded.hull.edge_clipped(i), payload.hull.edge_clipped(i));
      EXPECT_EQ(decoded.hull.edge_angle(i), payload.hull.edge_angle(i));
    }
    EXPECT_EQ(decoded.foreground_pixels, payload.foreground_pixels);
  }
}

TEST(HullCodec, AFortyVertexHullTakesUnder300Bytes) {
  HullPayload payload;
  payload.hull = PolygonHull(40);
  ASSERT_EQ(payload.hull.size(), 40);
  payload.foreground_pixels = 120000;
  EXPECT_LT(EncodeHull(payload).size(), 300u);
}

TEST(HullCodec, EmptyHullsRoundTrip) {
  HullPayload empty;
  HullPayload decoded;
  std::string error;
  ASSERT_TRUE(DecodeHull(EncodeHull(empty), 640, 480, &decoded, &error)) << error;
  EXPECT_TRUE(decoded.hull.empty());
}

TEST(HullCodec, RejectsCorruptionTruncationAndForgeries) {
  HullPayload payload;
  payload.hull = PolygonHull(30);
  const std::vector<uint8_t> good = EncodeHull(payload);
  HullPayload out;
  std::string error;
  // Every single-bit flip is caught.
  for (size_t byte = 0; byte < good.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> bad = good;
      bad[byte] ^= static_cast<uint8_t>(1u << bit);
      EXPECT_FALSE(DecodeHull(bad, 640, 480, &out, &error)) << byte << ":" << bit;
    }
  }
  for (size_t length = 0; length < good.size(); ++length) {
    EXPECT_FALSE(DecodeHull(std::span(good).first(length), 640, 480, &out, &error));
  }
  // A well-formed payload for a larger image does not fit a smaller one.
  EXPECT_FALSE(DecodeHull(good, 320, 240, &out, &error));
  EXPECT_NE(error.find("outside"), std::string::npos) << error;
  // A non-convex polygon with a valid checksum is still refused.
  std::vector<Eigen::Vector2d> star = {{10, 10}, {50, 10}, {30, 12}, {50, 50}, {10, 50}};
  HullPayload forged;
  forged.hull = SilhouetteHull(star, std::vector<bool>(star.size(), false));
  EXPECT_FALSE(DecodeHull(EncodeHull(forged), 640, 480, &out, &error));
  EXPECT_NE(error.find("convex"), std::string::npos) << error;
}

TEST(HullCodec, RandomBytesNeverCrash) {
  std::mt19937_64 rng(11);
  HullPayload out;
  std::string error;
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<uint8_t> bytes(rng() % 300);
    for (auto& b : bytes)
      b = static_cast<uint8_t>(rng());
    if (!bytes.empty() && trial % 2 == 0) bytes[0] = 1;
    EXPECT_FALSE(DecodeHull(bytes, 640, 480, &out, &error));
  }
}

}  // namespace
}  // namespace silnet
