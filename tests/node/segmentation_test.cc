// Background segmentation of the simulator's default noisy colour feed (lighting changes,
// shadows, sensor noise) against its exact silhouettes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "node/segmentation/silhouette_segmenter.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"

namespace silnet::node {
namespace {

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const double u = cv::countNonZero(a | b);
  return u == 0 ? 1.0 : cv::countNonZero(a & b) / u;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Median IoU per camera of `method` over the frames after warm-up of a `frames`-frame feed of
// an 8-camera ring (cameras in parallel).
std::vector<double> MedianIoUPerCamera(SegmentationMethod method, int frames, int cameras = 8) {
  sim::CameraNetworkOptions network;
  network.cameras = cameras;
  network.seed = 3;
  const auto models = sim::MakeCameraNetwork(network);
  sim::SceneOptions scene_options;
  scene_options.seed = 3;
  scene_options.time_begin = -2;
  scene_options.time_end = frames / 30.0 + 2;
  const sim::Scene scene(scene_options);
  SegmentationOptions options;
  options.method = method;
  std::vector<double> medians(static_cast<size_t>(cameras), 0.0);
  std::vector<size_t> counts(static_cast<size_t>(cameras), 0);
  ParallelFor(static_cast<size_t>(cameras), 0, [&](size_t c) {
    const sim::CameraRenderer renderer(models[c], scene, sim::RenderSettings{},
                                       static_cast<int>(c));
    SilhouetteSegmenter segmenter(options);
    std::vector<double> ious;
    for (int k = 0; k < frames; ++k) {
      cv::Mat truth, colour;
      renderer.Render(models[c].ExposureTime(k), static_cast<uint64_t>(k), &truth, &colour);
      const Segmentation s = segmenter.Segment(colour);
      if (!s.warming_up) ious.push_back(IoU(s.mask, truth));
    }
    counts[c] = ious.size();
    if (!ious.empty()) medians[c] = Median(ious);
  });
  for (int c = 0; c < cameras; ++c) {
    std::printf("%s camera %d: median IoU %.4f over %zu frames after warm-up\n",
                ToString(method).c_str(), c, medians[static_cast<size_t>(c)],
                counts[static_cast<size_t>(c)]);
    EXPECT_GE(counts[static_cast<size_t>(c)], static_cast<size_t>(frames / 2));
  }
  return medians;
}

TEST(Segmentation, MedianModelReachesIoU95OnEveryCamera) {
  for (double iou : MedianIoUPerCamera(SegmentationMethod::kMedian, 600))
    EXPECT_GE(iou, 0.95);
}

// OpenCV's models learn a subject that is in view from the start (and moves slowly) into their
// background, so on this feed they reach far lower IoU than the median model (measured:
// MOG2 0.4-0.6, KNN 0.7-0.86); they stay available for scenes that start empty.
TEST(Segmentation, OpenCvModelsSegmentTheSubject) {
  for (SegmentationMethod method : {SegmentationMethod::kMog2, SegmentationMethod::kKnn}) {
    for (double iou : MedianIoUPerCamera(method, 300, 2))
      EXPECT_GE(iou, 0.35) << ToString(method);
  }
}

TEST(Segmentation, MaskInputThresholdsAndCleansUp) {
  SegmentationOptions options;
  options.method = SegmentationMethod::kMaskInput;
  options.min_blob_area = 10;
  SilhouetteSegmenter segmenter(options);
  cv::Mat mask(60, 80, CV_8U, cv::Scalar(0));
  mask(cv::Rect(10, 10, 30, 30)).setTo(200);
  mask.at<uint8_t>(50, 70) = 255;         // a speck, removed
  mask(cv::Rect(20, 20, 2, 2)).setTo(0);  // a pinhole, filled
  const Segmentation s = segmenter.Segment(mask);
  EXPECT_FALSE(s.warming_up);
  EXPECT_EQ(s.cleanup.blobs, 1);
  EXPECT_EQ(cv::countNonZero(s.mask), 30 * 30);
}

TEST(Segmentation, RejectsFramesOfAnotherSizeOrType) {
  SilhouetteSegmenter segmenter(SegmentationOptions{});
  segmenter.Segment(cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  EXPECT_THROW(segmenter.Segment(cv::Mat(40, 64, CV_8UC3)), InputError);
  EXPECT_THROW(segmenter.Segment(cv::Mat(48, 64, CV_8UC1)), InputError);
  SegmentationOptions bad;
  bad.shadow_min_ratio = 2.0;
  EXPECT_THROW(SilhouetteSegmenter{bad}, InputError);
  std::string error;
  EXPECT_FALSE(bad.Set("no_such_setting", "1", &error));
  EXPECT_NE(error.find("unknown"), std::string::npos);
  EXPECT_FALSE(bad.Set("history", "many", &error));
  EXPECT_TRUE(bad.Set("threshold_sigmas", "5.5", &error));
  EXPECT_EQ(bad.threshold_sigmas, 5.5);
}

}  // namespace
}  // namespace silnet::node

namespace silnet::node {
namespace {

// Graph-cut refinement pulls a boundary that is a few pixels off back towards the silhouette.
TEST(Segmentation, GraphCutRefinementImprovesAnInexactBoundary) {
  sim::CameraNetworkOptions network;
  network.seed = 3;
  const auto cameras = sim::MakeCameraNetwork(network);
  sim::SceneOptions scene_options;
  scene_options.seed = 3;
  const sim::Scene scene(scene_options);
  double before = 0, after = 0;
  for (int c = 0; c < 4; ++c) {
    const sim::CameraRenderer renderer(cameras[static_cast<size_t>(c)], scene,
                                       sim::RenderSettings{}, c);
    cv::Mat truth, colour;
    renderer.Render(5.0 + c, 1, &truth, &colour);
    cv::Mat rough;
    cv::dilate(truth, rough, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
    before += IoU(rough, truth);
    RefineWithGraphCut(colour, &rough, 4);
    after += IoU(rough, truth);
  }
  std::printf("graph cut: mean IoU %.4f -> %.4f\n", before / 4, after / 4);
  EXPECT_GT(after, before + 0.04);
}

}  // namespace
}  // namespace silnet::node
