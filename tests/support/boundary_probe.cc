// silnet-boundary-probe: how far hulls from masks reach against a finer render of the same
// silhouettes. Give it a dataset rendered at 7x the size under test (silnet-sim generate
// --size 4480x3360 ... for 640x480): each coarse mask takes the 7x pixels whose centres
// coincide with its own (7x + 3, 7y + 3), so it is exactly the coarse render, and the 7x
// mask's hull, scaled down, stands for the true outline (its own error is a seventh). Prints
// the mean and rms support error of the coarse hulls, overall and per 15-degree band of
// image directions (0 = +x, 90 = +y, down). Silhouettes cut by the image border are left out;
// an unreadable mask, or one whose size is not a multiple of 7, stops it with the file named.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "shared/io/dataset_layout.h"
#include "shared/silhouette/silhouette_hull.h"

namespace {

constexpr int kScale = 7;
constexpr int kCentre = kScale / 2;  // the fine pixel whose centre is the coarse pixel's
constexpr int kBandDegrees = 15;

double Support(const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& direction) {
  double best = -1e300;
  for (const Eigen::Vector2d& p : points)
    best = std::max(best, direction.dot(p));
  return best;
}

// Running sums of signed errors.
struct ErrorSums {
  double sum = 0.0, squares = 0.0;
  long count = 0;
  void Add(double e) {
    sum += e;
    squares += e * e;
    ++count;
  }
  double mean() const { return sum / static_cast<double>(count); }
  double rms() const { return std::sqrt(squares / static_cast<double>(count)); }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: silnet-boundary-probe DATASET (rendered at 7x)\n");
    return 2;
  }
  const silnet::DatasetLayout layout(argv[1]);
  ErrorSums all;
  std::vector<ErrorSums> bands(360 / kBandDegrees);
  for (const std::string& camera : layout.CameraIds()) {
    const int masks = layout.CountImages(camera, "masks");
    for (int frame = 0; frame < masks; ++frame) {
      const std::string path = layout.MaskPath(camera, frame).string();
      const cv::Mat fine = cv::imread(path, cv::IMREAD_GRAYSCALE);
      if (fine.empty() || fine.cols % kScale != 0 || fine.rows % kScale != 0) {
        std::fprintf(stderr, "%s: unreadable, or its size is not a multiple of %d\n", path.c_str(),
                     kScale);
        return 1;
      }
      cv::Mat coarse(fine.rows / kScale, fine.cols / kScale, CV_8UC1);
      for (int y = 0; y < coarse.rows; ++y) {
        for (int x = 0; x < coarse.cols; ++x) {
          coarse.at<uint8_t>(y, x) = fine.at<uint8_t>(kScale * y + kCentre, kScale * x + kCentre);
        }
      }
      silnet::MaskSummary coarse_summary, fine_summary;
      const silnet::SilhouetteHull hull = silnet::ComputeSilhouetteHull(coarse, &coarse_summary);
      const silnet::SilhouetteHull truth = silnet::ComputeSilhouetteHull(fine, &fine_summary);
      if (hull.empty() || coarse_summary.touches_border || fine_summary.touches_border) continue;
      std::vector<Eigen::Vector2d> outline;
      for (const Eigen::Vector2d& v : truth.vertices()) {
        outline.push_back((v.array() + 0.5) / kScale - 0.5);
      }
      for (int degree = 0; degree < 360; ++degree) {
        const double angle = (degree + 0.5) * std::numbers::pi / 180.0;
        const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
        const double error = Support(hull.vertices(), direction) - Support(outline, direction);
        all.Add(error);
        bands[static_cast<size_t>(degree / kBandDegrees)].Add(error);
      }
    }
  }
  if (all.count == 0) {
    std::fprintf(stderr, "no silhouette inside the image under %s/*/masks\n", argv[1]);
    return 1;
  }
  std::printf("all directions: mean %+.3f px, rms %.3f px (%ld)\n", all.mean(), all.rms(),
              all.count);
  for (size_t b = 0; b < bands.size(); ++b) {
    std::printf("%3zu-%3zu deg: mean %+.3f px, rms %.3f px\n", b * kBandDegrees,
                (b + 1) * kBandDegrees, bands[b].mean(), bands[b].rms());
  }
  return 0;
}
