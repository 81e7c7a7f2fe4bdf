// The single-background segmenter of stills without masks.

#include "node/segmentation/background_difference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::node {
namespace {

// A textured background with mild sensor noise.
cv::Mat Background(int seed) {
  cv::Mat image(120, 160, CV_8UC3);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(image, cv::RNG::UNIFORM, cv::Scalar::all(60), cv::Scalar::all(190));
  return image;
}

cv::Mat WithNoise(const cv::Mat& image, int seed, double sigma = 3.0) {
  cv::Mat noise(image.size(), CV_16SC3), out;
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(sigma));
  image.convertTo(out, CV_16SC3);
  out += noise;
  out.convertTo(out, CV_8UC3);
  return out;
}

// Over seeds: a subject on the background is found to within its outline; its shadow, the
// background darkened to 60 %, is not taken for subject; noise leaves no specks.
TEST(BackgroundDifferenceTest, FindsTheSubjectAndNotItsShadow) {
  for (int seed = 1; seed <= 5; ++seed) {
    const cv::Mat background = Background(seed);
    cv::Mat still = background.clone();
    const cv::Rect shadow(90, 70, 50, 30);
    still(shadow).convertTo(still(shadow), CV_8UC3, 0.6);
    const cv::Rect subject(30, 20, 50, 60);
    still(subject).setTo(cv::Scalar(30, 40, 220));
    const BackgroundDifference result =
        SegmentAgainstBackground(WithNoise(still, 100 + seed), background);
    cv::Mat expected = cv::Mat::zeros(still.size(), CV_8UC1);
    expected(subject).setTo(255);
    EXPECT_LE(cv::norm(result.mask, expected, cv::NORM_L1) / 255, 8) << "seed " << seed;
    EXPECT_EQ(cv::countNonZero(result.mask(shadow)), 0) << "seed " << seed;
    EXPECT_EQ(result.cleanup.blobs, 1) << "seed " << seed;
  }
}

// A grey subject in front of a grey wall is darker with the wall's chromaticity, as a shadow
// would be, but carries its own texture: it is kept whole, while a real shadow beside it (the
// wall's texture, darkened evenly) is not taken.
TEST(BackgroundDifferenceTest, KeepsASubjectOfTheWallsColourThatIsNoShadow) {
  for (int seed = 1; seed <= 3; ++seed) {
    cv::Mat background(120, 160, CV_8UC3);
    cv::RNG rng(static_cast<uint64_t>(seed));
    cv::Mat grey(background.size(), CV_8UC1);
    rng.fill(grey, cv::RNG::UNIFORM, 150, 190);
    cv::cvtColor(grey, background, cv::COLOR_GRAY2BGR);
    cv::Mat still = background.clone();
    const cv::Rect subject(20, 20, 50, 70), shadow(100, 60, 40, 40);
    for (int y = subject.y; y < subject.br().y; ++y) {
      for (int x = subject.x; x < subject.br().x; ++x) {
        const double ratio = rng.uniform(0.45, 0.85);  // its own blotchy texture
        still.at<cv::Vec3b>(y, x) = background.at<cv::Vec3b>(y, x) * ratio;
      }
    }
    still(shadow).convertTo(still(shadow), CV_8UC3, 0.6);
    const BackgroundDifference result =
        SegmentAgainstBackground(WithNoise(still, 200 + seed), background);
    EXPECT_GT(cv::countNonZero(result.mask(subject)), 0.97 * subject.area()) << "seed " << seed;
    EXPECT_EQ(cv::countNonZero(result.mask(shadow)), 0) << "seed " << seed;
  }
}

// A subject in front of a faintly textured grey wall, with a hole through it that shows the
// wall and a patch of its own blotchy texture within the threshold of the wall's colour
// ("camouflage"), and the same two at its outline as notches: the camouflaged patch and notch
// are filled, the hole and the notch that shows the wall stay; without the camouflage test the
// patch would be a hole too.
TEST(BackgroundDifferenceTest, FillsCamouflagedPatchesButNotTrueHoles) {
  for (int seed = 1; seed <= 3; ++seed) {
    cv::RNG rng(static_cast<uint64_t>(seed));
    cv::Mat grey(120, 160, CV_8UC1), background;
    rng.fill(grey, cv::RNG::UNIFORM, 100, 105);
    cv::cvtColor(grey, background, cv::COLOR_GRAY2BGR);
    cv::Mat still = background.clone();
    const cv::Rect subject(30, 20, 80, 80), hole(42, 45, 16, 16), patch(78, 45, 16, 16);
    still(subject).setTo(cv::Scalar(40, 60, 200));
    background(hole).copyTo(still(hole));
    for (int y = patch.y; y < patch.br().y; ++y) {
      for (int x = patch.x; x < patch.br().x; ++x) {
        const int blotch = ((x / 4) * 7 + (y / 4) * 13 + seed) % 3 == 0 ? 6 : -6;
        for (int c = 0; c < 3; ++c) {
          still.at<cv::Vec3b>(y, x)[c] =
              cv::saturate_cast<uchar>(background.at<cv::Vec3b>(y, x)[c] + blotch);
        }
      }
    }
    // The same at the outline: a camouflaged notch in the right side, a notch in the left side
    // that shows the wall.
    const cv::Rect notch(100, 75, 10, 10), gap(30, 75, 10, 10);
    background(gap).copyTo(still(gap));
    for (int y = notch.y; y < notch.br().y; ++y) {
      for (int x = notch.x; x < notch.br().x; ++x) {
        for (int c = 0; c < 3; ++c) {
          still.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(
              background.at<cv::Vec3b>(y, x)[c] + ((x + y) / 3 % 2 == 0 ? 6 : -6));
        }
      }
    }
    const cv::Mat noisy = WithNoise(still, 300 + seed, 1.5);
    BackgroundDifferenceOptions options;
    options.camouflage.bay_radius_fraction = 0.06;  // 12 px on this small image
    const BackgroundDifference result = SegmentAgainstBackground(noisy, background, options);
    EXPECT_GE(cv::countNonZero(result.mask(patch)), 0.97 * patch.area()) << "seed " << seed;
    EXPECT_LE(cv::countNonZero(result.mask(hole)), 0.05 * hole.area()) << "seed " << seed;
    // Closing reaches all of the notch but its rim at the outline (82 of 100 pixels measured).
    EXPECT_GE(cv::countNonZero(result.mask(notch)), 0.75 * notch.area()) << "seed " << seed;
    EXPECT_LE(cv::countNonZero(result.mask(gap)), 0.1 * gap.area()) << "seed " << seed;
    EXPECT_GE(result.camouflaged_holes_filled, 2) << "seed " << seed;
    BackgroundDifferenceOptions plain;
    plain.fill_camouflaged_holes = false;
    const BackgroundDifference without = SegmentAgainstBackground(noisy, background, plain);
    EXPECT_LT(cv::countNonZero(without.mask(patch)), 0.5 * patch.area()) << "seed " << seed;
    EXPECT_LT(cv::countNonZero(without.mask(notch)), 0.5 * notch.area()) << "seed " << seed;
  }
}

// Asked to, it marks weak evidence beside the silhouette: a thin dark pole 8 DN off the wall
// (under the 12 DN threshold) that continues the subject is marked, a shadow near it (the wall
// darkened to 80 %) and an isolated faint patch are not.
TEST(BackgroundDifferenceTest, MarksWeakEvidenceBesideTheSilhouette) {
  cv::Mat grey(120, 160, CV_8UC1), background;
  cv::RNG rng(5);
  rng.fill(grey, cv::RNG::UNIFORM, 150, 153);
  cv::cvtColor(grey, background, cv::COLOR_GRAY2BGR);
  cv::Mat still = background.clone();
  const cv::Rect subject(40, 50, 40, 60), pole(58, 10, 3, 40), shadow(86, 80, 30, 30),
      patch(130, 10, 10, 10);
  still(subject).setTo(cv::Scalar(40, 60, 200));
  still(pole) -= cv::Scalar(8, 0, 3);
  still(shadow).convertTo(still(shadow), CV_8UC3, 0.8);
  still(patch) -= cv::Scalar(8, 0, 3);
  BackgroundDifferenceOptions options;
  options.mark_weak_silhouette = true;
  const BackgroundDifference marked =
      SegmentAgainstBackground(WithNoise(still, 7, 1.0), background, options);
  EXPECT_GE(cv::countNonZero(marked.mask(pole) == kWeakSilhouette), 0.8 * pole.area());
  EXPECT_EQ(cv::countNonZero(marked.mask(shadow) == kWeakSilhouette), 0);
  EXPECT_EQ(cv::countNonZero(marked.mask(patch)), 0);
  EXPECT_GE(cv::countNonZero(marked.mask(subject) == 255), 0.97 * subject.area());
  EXPECT_EQ(marked.weak_pixels, cv::countNonZero(marked.mask == kWeakSilhouette));
  // The subject's own contrast does not spill into the wall beside it (a blur over the whole
  // image marked a band one pixel wide all round it).
  cv::Mat ring = cv::Mat::zeros(still.size(), CV_8UC1);
  ring(cv::Rect(subject.x - 2, subject.y - 2, subject.width + 4, subject.height + 4)).setTo(255);
  ring(subject).setTo(0);
  ring(pole).setTo(0);
  EXPECT_EQ(cv::countNonZero(ring & (marked.mask == kWeakSilhouette)), 0);
  const BackgroundDifference plain = SegmentAgainstBackground(WithNoise(still, 7, 1.0), background);
  EXPECT_EQ(cv::countNonZero((plain.mask != 0) & (plain.mask != 255)), 0);
}

// A disc drawn with its outline pixels mixing its colour and the wall's by how much of each
// pixel it covers (8x8 samples per pixel), as a camera sees it: the silhouette is the pixels
// whose centre is inside, to within the pixels the disc covers about half of. The plain
// threshold takes the outline pixels it covers by a small fraction too, a band round the disc.
TEST(BackgroundDifferenceTest, DropsOutlinePixelsTheSubjectCoversLessThanHalf) {
  for (int seed = 1; seed <= 3; ++seed) {
    const cv::Mat background = Background(seed);
    cv::Mat still = background.clone();
    cv::Mat centres = cv::Mat::zeros(still.size(), CV_8UC1);
    cv::Mat coverage(still.size(), CV_64F, cv::Scalar(0.0));
    const cv::Point2d centre(80.3 + seed * 0.17, 60.6 - seed * 0.23);
    const double radius = 30.4;
    const cv::Vec3d colour(40, 60, 210);
    for (int y = 0; y < still.rows; ++y) {
      for (int x = 0; x < still.cols; ++x) {
        int in = 0;
        for (int j = 0; j < 8; ++j) {
          for (int i = 0; i < 8; ++i) {
            in += std::hypot(x - 0.5 + (i + 0.5) / 8 - centre.x,
                             y - 0.5 + (j + 0.5) / 8 - centre.y) < radius;
          }
        }
        const double a = in / 64.0;
        coverage.at<double>(y, x) = a;
        cv::Vec3b& pixel = still.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c)
          pixel[c] = cv::saturate_cast<uint8_t>(a * colour[c] + (1 - a) * pixel[c]);
        if (std::hypot(x - centre.x, y - centre.y) < radius) centres.at<uint8_t>(y, x) = 255;
      }
    }
    const cv::Mat photo = WithNoise(still, 300 + seed, 1.5);
    const cv::Mat uncertain = (coverage > 0.3) & (coverage < 0.7);
    const auto wrong = [&](const cv::Mat& mask) {
      return cv::countNonZero((mask != centres) & ~uncertain);
    };
    BackgroundDifferenceOptions plain;
    plain.trim_partly_covered_outline = false;
    const int before = wrong(SegmentAgainstBackground(photo, background, plain).mask);
    const BackgroundDifference trimmed = SegmentAgainstBackground(photo, background);
    EXPECT_GT(before, 20) << "seed " << seed;
    EXPECT_LE(wrong(trimmed.mask), 2) << "seed " << seed;
    EXPECT_GE(trimmed.outline_pixels_trimmed, before) << "seed " << seed;
  }
}

TEST(BackgroundDifferenceTest, RejectsImagesOfDifferentSizes) {
  EXPECT_THROW(SegmentAgainstBackground(Background(1), Background(1)(cv::Rect(0, 0, 20, 20))),
               InputError);
}

}  // namespace
}  // namespace silnet::node
