#include "node/segmentation/mask_cleanup.h"

#include <opencv2/imgproc.hpp>

#include "shared/silhouette/foreground_box.h"

namespace silnet::node {
namespace {

cv::Mat Disc(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

}  // namespace

CleanupStats CleanMask(cv::Mat* full_mask, const SegmentationOptions& options) {
  CleanupStats stats;
  // Work inside the foreground's bounding box, with room for the closing to grow.
  const int margin = options.close_radius + 1;
  const cv::Rect extent = ForegroundBox(*full_mask);
  if (extent.area() == 0) return stats;
  const cv::Rect box = cv::Rect(extent.x - margin, extent.y - margin, extent.width + 2 * margin,
                                extent.height + 2 * margin) &
                       cv::Rect(0, 0, full_mask->cols, full_mask->rows);
  cv::Mat mask = (*full_mask)(box);
  if (options.open_radius > 0)
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, Disc(options.open_radius));
  if (options.close_radius > 0)
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, Disc(options.close_radius));
  cv::Mat labels, stats_table, centroids;
  const int count =
      cv::connectedComponentsWithStats(mask, labels, stats_table, centroids, 8, CV_32S);
  std::vector<uint8_t> keep(static_cast<size_t>(count), 0);
  for (int i = 1; i < count; ++i) {
    if (stats_table.at<int>(i, cv::CC_STAT_AREA) >= options.min_blob_area) {
      keep[static_cast<size_t>(i)] = 1;
      ++stats.blobs;
    } else {
      ++stats.blobs_removed;
    }
  }
  if (stats.blobs_removed > 0) {
    for (int y = 0; y < mask.rows; ++y) {
      const int* label = labels.ptr<int>(y);
      uint8_t* out = mask.ptr<uint8_t>(y);
      for (int x = 0; x < mask.cols; ++x) {
        if (out[x] != 0 && keep[static_cast<size_t>(label[x])] == 0) out[x] = 0;
      }
    }
  }
  if (options.max_hole_area > 0 && stats.blobs > 0) {
    // Holes: background components inside the foreground's bounding box that do not touch
    // the box's border (4-connectivity, the dual of the 8-connected foreground).
    // (Not cv::boundingRect: OpenCV 4.6's box of a view like `mask` can come out too narrow.)
    const cv::Rect inner = ForegroundBox(mask);
    cv::Mat roi = mask(inner);
    cv::Mat background = roi == 0;
    cv::Mat hole_labels, hole_stats, hole_centroids;
    const int holes = cv::connectedComponentsWithStats(background, hole_labels, hole_stats,
                                                       hole_centroids, 4, CV_32S);
    for (int i = 1; i < holes; ++i) {
      const int x = hole_stats.at<int>(i, cv::CC_STAT_LEFT),
                y = hole_stats.at<int>(i, cv::CC_STAT_TOP);
      const int w = hole_stats.at<int>(i, cv::CC_STAT_WIDTH),
                h = hole_stats.at<int>(i, cv::CC_STAT_HEIGHT);
      const bool touches = x == 0 || y == 0 || x + w == inner.width || y + h == inner.height;
      if (touches || hole_stats.at<int>(i, cv::CC_STAT_AREA) > options.max_hole_area) continue;
      roi.setTo(255, hole_labels == i);
      ++stats.holes_filled;
    }
  }
  return stats;
}

void RefineWithGraphCut(const cv::Mat& frame, cv::Mat* mask, int band) {
  if (cv::countNonZero(*mask) == 0) return;
  const cv::Rect image(0, 0, mask->cols, mask->rows);
  cv::Rect box = cv::boundingRect(*mask);
  box = cv::Rect(box.x - 4 * band, box.y - 4 * band, box.width + 8 * band, box.height + 8 * band) &
        image;
  const cv::Mat roi_mask = (*mask)(box);
  cv::Mat inner, outer;
  cv::erode(roi_mask, inner, Disc(band));
  cv::dilate(roi_mask, outer, Disc(band));
  cv::Mat labels(roi_mask.size(), CV_8U, cv::Scalar(cv::GC_BGD));
  labels.setTo(cv::GC_PR_BGD, outer);
  labels.setTo(cv::GC_PR_FGD, roi_mask);
  labels.setTo(cv::GC_FGD, inner);
  if (cv::countNonZero(inner) == 0) return;  // too thin to anchor the colour models
  cv::Mat background_model, foreground_model;
  cv::grabCut(frame(box), labels, cv::Rect(), background_model, foreground_model, 1,
              cv::GC_INIT_WITH_MASK);
  cv::Mat refined = (labels == cv::GC_FGD) | (labels == cv::GC_PR_FGD);
  refined.copyTo(roi_mask);
}

}  // namespace silnet::node
