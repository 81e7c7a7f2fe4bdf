// The aggregator's readers of files users hand to its jobs, fed deterministic mutations of
// valid files (bit flips, random bytes, truncations, insertions): each mutated file must be
// read into something the jobs can use or refused with an InputError, never crash or escape
// with another exception. The readers: pairs.yaml and its matches CSV (`--pairs DIR`), a
// Utrecht camera's config.xml, a Middlebury `_par.txt`, a PBM mask, the INRIA dancer's and
// Tsinghua WD2's camera files and EPVH's camera and contour files.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <string>
#include <typeinfo>
#include <vector>

#include "aggregator/hulls/real_datasets.h"
#include "aggregator/pairwise/pairwise_job.h"
#include "aggregator/stereo/middlebury_dataset.h"
#include "shared/util/check.h"
#include "tests/support/byte_mutation.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void WriteBytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// The start of `bytes` with control characters escaped, for a failure message.
std::string Excerpt(const std::vector<uint8_t>& bytes) {
  std::string text;
  for (size_t i = 0; i < bytes.size() && i < 400; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c == '\n' || (c >= 32 && c < 127)) {
      text += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      text += hex;
    }
  }
  return text;
}

// How the mutations of one file fared.
struct MutationTally {
  int read = 0;
  int refused = 0;
};

// Writes `count` mutations of `file`'s current contents over it, one after the other, and
// runs `read` on each: a file read must keep the reader's promises (checked by `read`), one
// refused must be refused with InputError. Restores the file afterwards.
MutationTally ReadMutations(const fs::path& file, int count, const std::function<void()>& read) {
  const std::vector<uint8_t> seed = ReadBytes(file);
  std::mt19937 random(20261130);
  MutationTally tally;
  int failures = 0;
  for (int m = 0; m < count && failures < 5; ++m) {
    const std::vector<uint8_t> bytes = testing::MutateBytes(seed, random);
    WriteBytes(file, bytes);
    try {
      read();
      ++tally.read;
    } catch (const InputError&) {
      ++tally.refused;
    } catch (const std::exception& e) {
      ++failures;
      ADD_FAILURE() << file.filename() << " mutation " << m << " escaped as " << typeid(e).name()
                    << ": " << e.what() << "\n--- file ---\n"
                    << Excerpt(bytes);
    }
  }
  WriteBytes(file, seed);
  std::printf("%s: %d mutations read, %d refused\n", file.filename().c_str(), tally.read,
              tally.refused);
  return tally;
}

// What every reader of cameras promises: positive finite focal lengths, a rotation, a finite
// position, a positive image size.
void ExpectUsableCamera(const CameraModel& camera) {
  EXPECT_TRUE(camera.K.allFinite() && camera.R.allFinite() && camera.t.allFinite()) << camera.id;
  EXPECT_GT(camera.K(0, 0), 0.0) << camera.id;
  EXPECT_GT(camera.K(1, 1), 0.0) << camera.id;
  EXPECT_LT((camera.R * camera.R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-6)
      << camera.id;
  EXPECT_NEAR(camera.R.determinant(), 1.0, 1e-6) << camera.id;
  EXPECT_GT(camera.width, 0) << camera.id;
  EXPECT_GT(camera.height, 0) << camera.id;
}

TEST(InputFileMutations, PairsYamlAndItsMatches) {
  testing::TempDir dir;
  PairwiseJobResult result;
  PairwiseResult p;
  p.camera_i = "cam_a";
  p.camera_j = "cam_b";
  p.status = PairStatus::kAmbiguous;
  p.F << 0, -1e-4, 0.02, 1e-4, 0, -0.05, -0.02, 0.05, 1;
  p.offset = 1.25;
  p.offset_sigma = 0.1;
  p.residual_rms = 0.4;
  for (int k = 0; k < 4; ++k) {
    TimedMatch m;
    m.frame_i = static_cast<uint64_t>(10 + k);
    m.frame_j = static_cast<uint64_t>(11 + k);
    m.x_i = {100.0 + k, 200.0 - k};
    m.x_j_a = m.x_j_b = {300.0 + k, 40.0 + k};
    p.inlier_matches.push_back(m);
  }
  p.inliers = p.inlier_matches.size();
  PairCandidate alternative = p.Chosen();
  alternative.F(0, 2) = 0.03;
  alternative.support = 2;
  p.alternatives.push_back(alternative);
  result.pairs.push_back(p);
  WritePairsYaml(dir / "pairs.yaml", result);
  WriteMatchesCsv(dir / "matches", result);

  const auto read = [&] {
    for (const PairwiseResult& pair : ReadPairsYaml(dir / "pairs.yaml", dir / "matches")) {
      EXPECT_FALSE(pair.camera_i.empty() || pair.camera_j.empty());
      EXPECT_NE(pair.camera_i, pair.camera_j);
      EXPECT_TRUE(pair.F.allFinite());
      EXPECT_TRUE(std::isfinite(pair.offset));
      for (const TimedMatch& m : pair.inlier_matches)
        EXPECT_TRUE(m.x_i.allFinite() && m.x_j_a.allFinite() && m.x_j_b.allFinite());
    }
  };
  read();
  ASSERT_EQ(ReadPairsYaml(dir / "pairs.yaml", dir / "matches").front().inlier_matches.size(), 4u);
  EXPECT_GT(ReadMutations(dir / "pairs.yaml", 600, read).refused, 0);
  for (const auto& entry : fs::directory_iterator(dir / "matches"))
    EXPECT_GT(ReadMutations(entry.path(), 300, read).refused, 0);
  // A row that is not six numbers is refused by its number, not dropped.
  std::ofstream(dir / "matches" / "cam_a-cam_b.csv")
      << "frame_i,frame_j,x_i,y_i,x_j,y_j\n10,11,1.5,2,3,4\n\n11,12,1,2,3,nan\n";
  EXPECT_THAT([&] { ReadPairsYaml(dir / "pairs.yaml", dir / "matches"); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("cam_a-cam_b.csv: row 4")));
  std::ofstream(dir / "matches" / "cam_a-cam_b.csv")
      << "frame_i,frame_j,x_i,y_i,x_j,y_j\n-1,11,1.5,2,3,4\n";
  EXPECT_THAT([&] { ReadPairsYaml(dir / "pairs.yaml", dir / "matches"); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("cam_a-cam_b.csv: row 2")));
  // Whole rows, but fewer than the pair's inliers: a file cut short.
  std::ofstream(dir / "matches" / "cam_a-cam_b.csv")
      << "frame_i,frame_j,x_i,y_i,x_j,y_j\n10,11,1.5,2,3,4\n11,12,1,2,3,4\n";
  EXPECT_THAT([&] { ReadPairsYaml(dir / "pairs.yaml", dir / "matches"); },
              ::testing::ThrowsMessage<InputError>(
                  ::testing::HasSubstr("cam_a-cam_b.csv: 2 correspondences where")));
}

TEST(InputFileMutations, UtrechtCameraConfig) {
  testing::TempDir dir;
  const fs::path camera = dir / "cam1";
  fs::create_directories(camera);
  cv::VideoWriter video((camera / "video.avi").string(),
                        cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, cv::Size(32, 24));
  ASSERT_TRUE(video.isOpened());
  video.write(cv::Mat(24, 32, CV_8UC3, cv::Scalar(90, 90, 90)));
  video.release();
  {
    cv::FileStorage config((camera / "config.xml").string(), cv::FileStorage::WRITE);
    config << "CameraMatrix" << cv::Mat(cv::Matx33d(40, 0, 16, 0, 40, 12, 0, 0, 1))
           << "DistortionCoeffs" << cv::Mat(cv::Vec<double, 5>(-0.3, 0.1, 0, 0, 0)) << "Rotation"
           << cv::Mat(cv::Vec3d(0.0, 0.1, 0.2)) << "Translation" << cv::Mat(cv::Vec3d(1, 2, 3000));
  }
  const auto read = [&] {
    for (const CameraModel& c : LoadUtrechtCameras(dir.path(), 25.0))
      ExpectUsableCamera(c);
  };
  read();
  EXPECT_GT(ReadMutations(camera / "config.xml", 600, read).refused, 0);
}

TEST(InputFileMutations, MiddleburyParameters) {
  testing::TempDir dir;
  std::string par = "2\n";
  for (int v = 0; v < 2; ++v) {
    cv::Mat image(48, 64, CV_8UC3, cv::Scalar(0, 0, 0));
    cv::rectangle(image, cv::Rect(20 + 4 * v, 12, 20, 24), cv::Scalar(200, 180, 160), cv::FILLED);
    const std::string name = "objR000" + std::to_string(v + 1) + ".png";
    ASSERT_TRUE(cv::imwrite((dir / name).string(), image));
    par +=
        name + " 60 0 32 0 60 24 0 0 1  1 0 0 0 1 0 0 0 1  " + std::to_string(0.1 * v) + " 0 1\n";
  }
  std::ofstream(dir / "objR_par.txt") << par;
  const auto read = [&] {
    for (const StereoView& view : LoadMiddlebury(dir.path()).views) {
      ExpectUsableCamera(view.camera);
      EXPECT_EQ(view.mask.size(), view.image.size());
    }
  };
  read();
  EXPECT_GT(ReadMutations(dir / "objR_par.txt", 1500, read).refused, 0);
}

TEST(InputFileMutations, PbmMask) {
  testing::TempDir dir;
  std::string pbm = "P4\n# a comment\n13 3\n";
  for (int row = 0; row < 3; ++row)
    pbm += std::string{'\xf0', static_cast<char>(0x18 + row)};
  std::ofstream(dir / "mask.pbm", std::ios::binary) << pbm;
  const auto read = [&] {
    const cv::Mat mask = ReadPbm(dir / "mask.pbm", 1);
    EXPECT_EQ(mask.type(), CV_8UC1);
    EXPECT_FALSE(mask.empty());
  };
  read();
  EXPECT_EQ(cv::countNonZero(ReadPbm(dir / "mask.pbm", 1)), 3 * 6);  // 4 + 2 bits a row
  EXPECT_GT(ReadMutations(dir / "mask.pbm", 1500, read).refused, 0);
}

TEST(InputFileMutations, InriaDancerParameters) {
  testing::TempDir dir;
  std::string pbm = "P4\n16 4\n";
  for (int row = 0; row < 4; ++row)
    pbm += std::string{'\x0f', '\xf0'};
  std::ofstream(dir / "a.pbm", std::ios::binary) << pbm;
  std::ofstream(dir / "b.pbm", std::ios::binary) << pbm;
  std::ofstream(dir / "dancer_par.txt") << "2\na.pbm 20 0 8 1\n0 20 2 2\n0 0 1 5\n"
                                        << "b.pbm 19 1 8 -1\n-1 20 2 2\n0.02 0 1 6\n";
  const auto read = [&] {
    const RealCapture capture = LoadInriaDancer(dir.path());
    ASSERT_EQ(capture.cameras.size(), capture.masks.size());
    for (const CameraModel& camera : capture.cameras)
      ExpectUsableCamera(camera);
  };
  read();
  EXPECT_GT(ReadMutations(dir / "dancer_par.txt", 600, read).refused, 0);
}

TEST(InputFileMutations, TsinghuaWd2Parameters) {
  testing::TempDir dir;
  fs::create_directories(dir / "silhouettes");
  std::string calib;
  for (int index = 0; index < 2; ++index) {
    cv::Mat silhouette(24, 32, CV_8UC1, cv::Scalar(0));
    cv::rectangle(silhouette, cv::Rect(10, 6, 12, 12), cv::Scalar(255), cv::FILLED);
    ASSERT_TRUE(cv::imwrite(
        (dir / "silhouettes" / ("WD2_" + std::to_string(index) + "_00020_segmented.png")).string(),
        silhouette));
    calib += std::to_string(index) +
             "\n40 -0.1 16\n0 40 12\n0 0 1\n-0.04 0.06\n"
             "0.995004 0 0.099833 0.1\n0 1 0 0\n-0.099833 0 0.995004 " +
             std::to_string(3 + index) + "\n";
  }
  std::ofstream(dir / "calibParamsI.txt") << calib;
  const auto read = [&] {
    const RealCapture capture = LoadTsinghuaWd2(dir.path(), true);
    ASSERT_EQ(capture.cameras.size(), capture.masks.size());
    for (const CameraModel& camera : capture.cameras) {
      ExpectUsableCamera(camera);
      EXPECT_TRUE(camera.dist.allFinite());
    }
  };
  read();
  EXPECT_GT(ReadMutations(dir / "calibParamsI.txt", 600, read).refused, 0);
}

TEST(InputFileMutations, EpvhCamerasAndContours) {
  testing::TempDir dir;
  std::ofstream(dir / "alien-camera.txt")
      << "1500 0 950 10\n0 1500 800 20\n0 0 1 3\n\n1400 30 960 -5\n-20 1500 790 8\n0.01 0 1 2.5\n";
  std::ofstream(dir / "alien-contour.txt") << "0 4\n900 700\n1000 700\n1000 900\n900 900\n"
                                           << "1 3\n940 720\n1020 760\n930 880\n";
  const auto read = [&] {
    const RealCapture capture = LoadEpvhAlien(dir.path(), 2);
    ASSERT_EQ(capture.cameras.size(), capture.masks.size());
    for (size_t c = 0; c < capture.cameras.size(); ++c) {
      ExpectUsableCamera(capture.cameras[c]);
      EXPECT_EQ(capture.masks[c].cols, capture.cameras[c].width);
      EXPECT_EQ(capture.masks[c].rows, capture.cameras[c].height);
    }
  };
  read();
  EXPECT_GT(ReadMutations(dir / "alien-camera.txt", 300, read).refused, 0);
  EXPECT_GT(ReadMutations(dir / "alien-contour.txt", 300, read).refused, 0);
}

}  // namespace
}  // namespace silnet::aggregator
