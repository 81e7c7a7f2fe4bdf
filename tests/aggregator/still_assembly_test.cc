// Still reassembly (aggregator/ingest/still_assembly.h) and the collected stills as stereo
// views (still_views.h): chunks in any order, duplicates, corrupt and inconsistent chunks,
// images that do not decode, the missing ranges asked for again; cameras carried over to the
// still's resolution; the frame a reference time asks for.

#include "aggregator/ingest/still_assembly.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "aggregator/ingest/still_views.h"
#include "shared/util/check.h"
#include "shared/util/crc32.h"

namespace silnet::aggregator {
namespace {

// An encoded image split into Still samples the way a node sends them.
class WireStill {
 public:
  WireStill(std::vector<uint8_t> bytes, silnet_wire_StillPart part, size_t chunk_bytes, int width,
            int height, uint64_t frame = 7, const char* encoding = "png")
      : bytes_(std::move(bytes)) {
    const size_t count = (bytes_.size() + chunk_bytes - 1) / chunk_bytes;
    for (size_t i = 0; i < count; ++i) {
      const size_t begin = i * chunk_bytes, end = std::min(bytes_.size(), begin + chunk_bytes);
      data_.emplace_back(bytes_.begin() + static_cast<std::ptrdiff_t>(begin),
                         bytes_.begin() + static_cast<std::ptrdiff_t>(end));
      silnet_wire_Still s{};
      std::snprintf(s.camera_id, sizeof(s.camera_id), "cam00");
      s.still_id = 42;
      s.part = part;
      s.chunk_index = static_cast<uint32_t>(i);
      s.chunk_count = static_cast<uint32_t>(count);
      s.frame_index = frame;
      s.image_width = static_cast<uint16_t>(width);
      s.image_height = static_cast<uint16_t>(height);
      std::snprintf(s.encoding, sizeof(s.encoding), "%s", encoding);
      s.image_bytes = bytes_.size();
      s.image_crc32 = Crc32(0, bytes_.data(), bytes_.size());
      s.chunk_crc32 = Crc32(0, data_.back().data(), data_.back().size());
      samples_.push_back(s);
    }
    for (size_t i = 0; i < samples_.size(); ++i) {
      samples_[i].data._buffer = data_[i].data();
      samples_[i].data._length = static_cast<uint32_t>(data_[i].size());
    }
  }
  size_t size() const { return samples_.size(); }
  silnet_wire_Still& operator[](size_t i) { return samples_[i]; }
  std::vector<uint8_t>& data(size_t i) { return data_[i]; }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<uint8_t> bytes_;
  std::vector<std::vector<uint8_t>> data_;
  std::vector<silnet_wire_Still> samples_;
};

cv::Mat NoisyPhoto(int width, int height) {
  cv::Mat photo(height, width, CV_8UC3);
  cv::randu(photo, 0, 255);
  return photo;
}

std::vector<uint8_t> Png(const cv::Mat& image) {
  std::vector<uint8_t> bytes;
  cv::imencode(".png", image, bytes);
  return bytes;
}

cv::Mat Disc(int width, int height) {
  cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
  cv::circle(mask, {width / 2, height / 2}, height / 3, 255, -1);
  return mask;
}

TEST(StillAssembly, ChunksInAnyOrderWithDuplicatesGiveTheImageBack) {
  const cv::Mat photo = NoisyPhoto(64, 48);
  WireStill wire(Png(photo), silnet_wire_STILL_PHOTO, 1000, 64, 48);
  ASSERT_GT(wire.size(), 5u);
  StillPartAssembly part;
  std::vector<size_t> order(wire.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  for (size_t i : order) {
    EXPECT_FALSE(part.Complete());
    EXPECT_EQ(part.Accept(wire[i]), ChunkVerdict::kAccepted);
    EXPECT_EQ(part.Accept(wire[i]), ChunkVerdict::kDuplicate);
  }
  EXPECT_TRUE(part.Complete());
  EXPECT_TRUE(part.Missing().empty());
  EXPECT_EQ(part.Bytes(), wire.bytes());
}

TEST(StillAssembly, ACorruptChunkIsRejectedListedMissingAndTakenWhenSentAgain) {
  WireStill wire(Png(NoisyPhoto(64, 48)), silnet_wire_STILL_PHOTO, 1000, 64, 48);
  StillPartAssembly part;
  wire.data(2)[10] ^= 0x40;  // flipped on the way
  for (size_t i = 0; i < wire.size(); ++i) {
    if (i == 4) continue;  // lost
    const ChunkVerdict verdict = part.Accept(wire[i]);
    EXPECT_EQ(verdict, i == 2 ? ChunkVerdict::kCorrupt : ChunkVerdict::kAccepted) << i;
  }
  EXPECT_FALSE(part.Complete());
  const std::vector<std::pair<uint32_t, uint32_t>> missing{{2, 2}, {4, 4}};
  EXPECT_EQ(part.Missing(), missing);
  wire.data(2)[10] ^= 0x40;  // sent again, intact
  EXPECT_EQ(part.Accept(wire[2]), ChunkVerdict::kAccepted);
  EXPECT_EQ(part.Accept(wire[4]), ChunkVerdict::kAccepted);
  EXPECT_TRUE(part.Complete());
  EXPECT_EQ(part.Bytes(), wire.bytes());
}

TEST(StillAssembly, ChunksThatDisagreeWithTheStillAreMalformed) {
  WireStill wire(Png(NoisyPhoto(64, 48)), silnet_wire_STILL_PHOTO, 1000, 64, 48);
  StillPartAssembly part;
  ASSERT_EQ(part.Accept(wire[0]), ChunkVerdict::kAccepted);
  silnet_wire_Still other = wire[1];
  other.chunk_count += 1;
  EXPECT_EQ(part.Accept(other), ChunkVerdict::kMalformed);
  other = wire[1];
  other.image_width = 65;
  EXPECT_EQ(part.Accept(other), ChunkVerdict::kMalformed);
  other = wire[1];
  other.chunk_index = other.chunk_count;
  EXPECT_EQ(part.Accept(other), ChunkVerdict::kMalformed);
  other = wire[1];
  std::snprintf(other.encoding, sizeof(other.encoding), "gif");
  EXPECT_EQ(part.Accept(other), ChunkVerdict::kMalformed);
  other = wire[1];
  other.data._length = 0;
  other.data._buffer = nullptr;
  other.chunk_crc32 = 0;
  other.image_bytes = 0;
  EXPECT_EQ(part.Accept(other), ChunkVerdict::kMalformed);
}

TEST(StillAssembly, IntactChunksThatDoNotAddUpAreAllFetchedAgain) {
  WireStill wire(Png(NoisyPhoto(64, 48)), silnet_wire_STILL_PHOTO, 1000, 64, 48);
  // One chunk is intact on the wire but not the one the image was made of (its CRC is of
  // its own bytes): the whole image's CRC-32 gives it away.
  wire.data(1)[0] ^= 0x01;
  wire[1].chunk_crc32 = Crc32(0, wire.data(1).data(), wire.data(1).size());
  StillPartAssembly part;
  for (size_t i = 0; i + 1 < wire.size(); ++i)
    EXPECT_EQ(part.Accept(wire[i]), ChunkVerdict::kAccepted);
  EXPECT_EQ(part.Accept(wire[wire.size() - 1]), ChunkVerdict::kMalformed);
  EXPECT_FALSE(part.Complete());
  const std::vector<std::pair<uint32_t, uint32_t>> all{{0, static_cast<uint32_t>(wire.size() - 1)}};
  EXPECT_EQ(part.Missing(), all);
}

TEST(StillAssembly, DecodesPhotoAndSilhouetteAndRefusesAnImageThatIsNotWhatWasAnnounced) {
  const cv::Mat photo = NoisyPhoto(64, 48), mask = Disc(64, 48);
  WireStill photo_wire(Png(photo), silnet_wire_STILL_PHOTO, 4000, 64, 48);
  WireStill mask_wire(Png(mask), silnet_wire_STILL_SILHOUETTE, 4000, 64, 48);
  StillAssembly still(42);
  for (size_t i = 0; i < photo_wire.size(); ++i)
    still.Accept(photo_wire[i]);
  cv::Mat decoded_photo, decoded_mask;
  EXPECT_EQ(still.Decode(&decoded_photo, &decoded_mask), "incomplete");
  for (size_t i = 0; i < mask_wire.size(); ++i)
    still.Accept(mask_wire[i]);
  ASSERT_TRUE(still.Complete());
  ASSERT_EQ(still.Decode(&decoded_photo, &decoded_mask), "");
  EXPECT_EQ(cv::norm(decoded_photo, photo, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(decoded_mask, mask, cv::NORM_INF), 0.0);
  EXPECT_EQ(still.counts().accepted, photo_wire.size() + mask_wire.size());

  // A photo announced larger than it decodes: refused, its chunks fetched again.
  WireStill liar(Png(photo), silnet_wire_STILL_PHOTO, 4000, 80, 60);
  StillAssembly other(42);
  for (size_t i = 0; i < liar.size(); ++i)
    other.Accept(liar[i]);
  for (size_t i = 0; i < mask_wire.size(); ++i)
    other.Accept(mask_wire[i]);
  ASSERT_TRUE(other.Complete());
  EXPECT_NE(other.Decode(&decoded_photo, &decoded_mask).find("announced 80x60"), std::string::npos);
  EXPECT_FALSE(other.Complete());
  EXPECT_EQ(other.part(silnet_wire_STILL_PHOTO).Missing().size(), 1u);
  EXPECT_TRUE(other.part(silnet_wire_STILL_SILHOUETTE).Complete());

  // A chunk of another still is not this one's.
  silnet_wire_Still foreign = mask_wire[0];
  foreign.still_id = 43;
  EXPECT_EQ(still.Accept(foreign), ChunkVerdict::kMalformed);
}

TEST(StillViews, ACameraCarriedOverToAnotherResolutionSeesTheSamePoints) {
  CameraModel camera;
  camera.id = "cam00";
  camera.width = 640;
  camera.height = 480;
  camera.K << 500, 0, 322.5, 0, 505, 238.25, 0, 0, 1;
  camera.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized()).toRotationMatrix();
  camera.t = Eigen::Vector3d(0.1, -0.2, 4.0);
  camera.dist << -0.1, 0.02, 0, 0, 0;
  const CameraModel big = CameraAtImageSize(camera, 1920, 1440);
  EXPECT_EQ(big.width, 1920);
  EXPECT_EQ(big.height, 1440);
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.5, -0.3, 0.2)}) {
    const Eigen::Vector2d small_px = *camera.Project(point), big_px = *big.Project(point);
    EXPECT_NEAR(big_px.x(), 3.0 * (small_px.x() + 0.5) - 0.5, 1e-9);
    EXPECT_NEAR(big_px.y(), 3.0 * (small_px.y() + 0.5) - 0.5, 1e-9);
  }
  EXPECT_THROW(CameraAtImageSize(camera, 1920, 1080), InputError);
}

TEST(StillViews, TheFrameOfAReferenceTimeIsTheFirstExposedAtOrAfterIt) {
  CameraModel camera;
  camera.fps = 25.0;
  camera.time_offset = 3.4;
  const uint64_t k = FirstFrameAtOrAfter(camera, 2.0);
  EXPECT_EQ(k, 47u);
  EXPECT_GE((static_cast<double>(k) + camera.time_offset) / camera.fps, 2.0);
  EXPECT_LT((static_cast<double>(k) - 1.0 + camera.time_offset) / camera.fps, 2.0);
  EXPECT_EQ(FirstFrameAtOrAfter(camera, 0.0), 0u);
}

TEST(StillViews, OnlyCompleteStillsOfCalibratedCamerasWithASilhouetteBecomeViews) {
  CameraModel camera;
  camera.width = 64;
  camera.height = 48;
  camera.K << 60, 0, 31.5, 0, 60, 23.5, 0, 0, 1;
  std::vector<CameraModel> cameras(3, camera);
  cameras[0].id = "cam00";
  cameras[1].id = "cam01";
  cameras[2].id = "cam02";
  StillCollection collection;
  auto still = [](const std::string& id, bool complete, cv::Mat mask) {
    CollectedStill s;
    s.camera_id = id;
    s.complete = complete;
    s.reason = complete ? "" : "its node did not answer";
    s.photo = NoisyPhoto(mask.cols, mask.rows);
    s.silhouette = mask;
    return s;
  };
  collection.cameras = {still("cam00", true, Disc(128, 96)), still("cam01", false, Disc(64, 48)),
                        still("cam02", true, cv::Mat::zeros(48, 64, CV_8UC1)),
                        still("cam09", true, Disc(64, 48)), still("cam01", true, Disc(64, 48))};
  collection.cameras.back().frame_flags = silnet_wire_FRAME_WARMUP | silnet_wire_FRAME_CLIPPED;
  const StereoViews views = StillViews(collection, cameras);
  ASSERT_EQ(views.views.size(), 1u);
  EXPECT_EQ(views.views[0].camera.id, "cam00");
  EXPECT_EQ(views.views[0].camera.width, 128);
  EXPECT_NEAR(views.views[0].camera.K(0, 0), 120.0, 1e-12);
  ASSERT_EQ(views.warnings.size(), 4u);
  EXPECT_NE(views.warnings[0].find("cam01: no still (its node did not answer)"), std::string::npos);
  EXPECT_NE(views.warnings[1].find("cam02: empty silhouette"), std::string::npos);
  EXPECT_NE(views.warnings[2].find("cam09: not in the calibration"), std::string::npos);
  EXPECT_NE(views.warnings[3].find("cam01: its silhouette is from the background model's warm-up"),
            std::string::npos);
}

}  // namespace
}  // namespace silnet::aggregator
