#include "aggregator/stereo/missed_pixel_reach.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/stereo/coverage_restore.h"
#include "aggregator/stereo/uncoverable_pixels.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Check rounds after a round's moves before all of its moves left are undone.
constexpr int kCheckRounds = 4;
// A vertex projecting closer than this to its pixel's centre cannot be moved towards it.
constexpr double kMinImageMovePx = 0.05;

// A view's fixed pixel sets: inner (covered by any consistent model) and outer (by none).
struct PixelSets {
  cv::Mat inner, outer;
};

// Every view rendered from `mesh`.
std::vector<cv::Mat> RenderAll(const std::vector<StereoView>& views, const TriangleMesh& mesh,
                               int threads) {
  std::vector<cv::Mat> rendered(views.size());
  ParallelFor(views.size(), threads,
              [&](size_t v) { rendered[v] = RenderMeshSilhouette(mesh, views[v].camera); });
  return rendered;
}

// The vertices' pixels in one view, bucketed in square cells for the search around a pixel.
class ProjectedVertices {
 public:
  ProjectedVertices(const TriangleMesh& mesh, const Matrix34d& projection, const cv::Size& image,
                    double cell)
      : cell_(cell),
        columns_(static_cast<int>(std::ceil(image.width / cell)) + 1),
        rows_(static_cast<int>(std::ceil(image.height / cell)) + 1),
        pixels_(mesh.vertices.size()),
        head_(static_cast<size_t>(columns_ * rows_), -1),
        next_(mesh.vertices.size(), -1) {
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Eigen::Vector3d p = projection * mesh.vertices[i].cast<double>().homogeneous();
      if (p.z() <= 0) continue;
      pixels_[i] = p.hnormalized();
      const int cell_index = Cell(pixels_[i]);
      if (cell_index < 0) continue;
      next_[i] = head_[static_cast<size_t>(cell_index)];
      head_[static_cast<size_t>(cell_index)] = static_cast<int>(i);
    }
  }

  // Calls visit(vertex, its pixel) for the vertices projecting within `radius` (<= the
  // cell size) of `pixel`.
  template <typename Visit>
  void Near(const Eigen::Vector2d& pixel, double radius, Visit visit) const {
    const int cx = static_cast<int>(std::floor(pixel.x() / cell_));
    const int cy = static_cast<int>(std::floor(pixel.y() / cell_));
    for (int y = cy - 1; y <= cy + 1; ++y) {
      for (int x = cx - 1; x <= cx + 1; ++x) {
        if (x < 0 || y < 0 || x >= columns_ || y >= rows_) continue;
        for (int i = head_[static_cast<size_t>(y * columns_ + x)]; i >= 0;
             i = next_[static_cast<size_t>(i)]) {
          const Eigen::Vector2d& at = pixels_[static_cast<size_t>(i)];
          if ((at - pixel).norm() <= radius) visit(i, at);
        }
      }
    }
  }

 private:
  int Cell(const Eigen::Vector2d& pixel) const {
    if (!(pixel.x() >= 0 && pixel.y() >= 0)) return -1;
    const int x = static_cast<int>(pixel.x() / cell_), y = static_cast<int>(pixel.y() / cell_);
    return x < columns_ && y < rows_ ? y * columns_ + x : -1;
  }

  double cell_;
  int columns_, rows_;
  std::vector<Eigen::Vector2d> pixels_;
  std::vector<int> head_, next_;
};

// A vertex's move of a round.
struct Move {
  int vertex;
  Eigen::Vector3f from, to;
};

// Proposes one move per coverable missed pixel of view `v`: the vertex not yet `taken`
// nearest the pixel's reach among those projecting within the search radius, moved onto
// the reach and `beyond_px` past the pixel centre, where that stays within the largest move
// of where the vertex was at the start (`starts`). Counts the coverable pixels.
size_t ProposeMoves(const std::vector<StereoView>& views, const GrownSilhouettes& grown, size_t v,
                    const cv::Mat& missed, const TriangleMesh& mesh,
                    const std::vector<Eigen::Vector3f>& starts, double footprint,
                    const PixelReachOptions& options, std::vector<uint8_t>& taken,
                    std::vector<Move>& moves) {
  const Matrix34d& projection = grown.projections[v];
  const ProjectedVertices projected(mesh, projection, missed.size(), options.search_px);
  const double max_move = options.max_move_footprints * footprint;
  size_t coverable = 0;
  for (int y = 0; y < missed.rows; ++y) {
    const uint8_t* row = missed.ptr<uint8_t>(y);
    for (int x = 0; x < missed.cols; ++x) {
      if (row[x] == 0) continue;
      const Eigen::Vector2d pixel(x, y);
      const RayReach reach = CoverableReach(views, grown, v, pixel);
      if (reach.stretches.empty()) continue;
      ++coverable;
      int best = -1;
      double best_distance = std::numeric_limits<double>::infinity();
      Eigen::Vector3d best_target;
      projected.Near(pixel, options.search_px, [&](int i, const Eigen::Vector2d& at) {
        const auto k = static_cast<size_t>(i);
        if (taken[k] != 0) return;
        const Eigen::Vector3d from = mesh.vertices[k].cast<double>();
        const Eigen::Vector3d onto = reach.NearestPoint(from);
        const double distance = (onto - from).norm();
        const double image_move = (pixel - at).norm();
        if (distance >= best_distance || image_move < kMinImageMovePx) return;
        const Eigen::Vector3d target = onto + (onto - from) * (options.beyond_px / image_move);
        if ((target - starts[k].cast<double>()).norm() > max_move) return;
        best = i;
        best_distance = distance;
        best_target = target;
      });
      if (best < 0) continue;
      taken[static_cast<size_t>(best)] = 1;
      moves.push_back({best, mesh.vertices[static_cast<size_t>(best)], best_target.cast<float>()});
    }
  }
  return coverable;
}

// Pixels the moves made wrong in view `v`: outer pixels covered that were not, inner pixels
// missed that were covered.
cv::Mat NewlyWrong(const PixelSets& sets, const cv::Mat& before, const cv::Mat& after) {
  const cv::Mat newly_covered = after & ~before;
  const cv::Mat newly_missed = before & ~after;
  return (sets.outer & newly_covered) | (sets.inner & newly_missed);
}

// Undoes the moves (applied to `mesh`) near the pixels they made wrong in any view against
// `before` (the views rendered without them), within 2, 4, 6 px, then all that are left, until
// no view has such a pixel; `undone` gets a flag per move. Returns the views rendered after.
std::vector<cv::Mat> UndoHarmfulMoves(const std::vector<StereoView>& views,
                                      const std::vector<PixelSets>& sets,
                                      const std::vector<Matrix34d>& projections,
                                      const std::vector<cv::Mat>& before,
                                      const std::vector<Move>& moves, int threads,
                                      TriangleMesh* mesh, std::vector<uint8_t>* undone) {
  undone->assign(moves.size(), 0);
  std::vector<cv::Mat> after = RenderAll(views, *mesh, threads);
  for (int check = 0;; ++check) {
    std::vector<cv::Mat> wrong(views.size());
    bool any = false;
    for (size_t v = 0; v < views.size(); ++v) {
      wrong[v] = NewlyWrong(sets[v], before[v], after[v]);
      any = any || cv::countNonZero(wrong[v]) > 0;
    }
    if (!any) return after;
    const int radius = 2 + 2 * check;
    const cv::Mat disc =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
    for (size_t v = 0; v < views.size(); ++v) {
      if (cv::countNonZero(wrong[v]) == 0) continue;
      cv::Mat near;
      cv::dilate(wrong[v], near, disc);
      for (size_t k = 0; k < moves.size(); ++k) {
        if ((*undone)[k] != 0) continue;
        if (check + 1 < kCheckRounds && !ProjectsOntoMarkedPixel(near, projections[v], moves[k].to))
          continue;
        (*undone)[k] = 1;
        mesh->vertices[static_cast<size_t>(moves[k].vertex)] = moves[k].from;
      }
    }
    after = RenderAll(views, *mesh, threads);
  }
}

}  // namespace

bool PixelReachOptions::IsValid(std::string* reason) const {
  const auto fail = [&](const std::string& why) {
    if (reason) *reason = why;
    return false;
  };
  if (rounds < 0) return fail(fmt::format("pixel reach rounds must be >= 0 (got {})", rounds));
  if (!(search_px > 0 && search_px <= 16))
    return fail(fmt::format("pixel reach search must be in (0, 16] px (got {})", search_px));
  if (!(max_move_footprints > 0))
    return fail(
        fmt::format("pixel reach move must be > 0 footprints (got {})", max_move_footprints));
  if (!(beyond_px >= 0 && beyond_px < 1))
    return fail(fmt::format("pixel reach beyond must be in [0, 1) px (got {})", beyond_px));
  if (!(margin_px >= 0)) return fail(fmt::format("margin must be >= 0 (got {})", margin_px));
  return true;
}

PixelReachStats ReachMissedPixels(const std::vector<StereoView>& views, double footprint,
                                  const PixelReachOptions& options, TriangleMesh* mesh) {
  SILNET_CHECK(footprint > 0 && mesh != nullptr);
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  const auto start = std::chrono::steady_clock::now();
  PixelReachStats stats;
  std::vector<PixelSets> sets(views.size());
  for (size_t v = 0; v < views.size(); ++v)
    sets[v].inner = InnerSilhouettePixels(views[v].mask, options.margin_px);
  std::vector<cv::Mat> rendered = RenderAll(views, *mesh, options.threads);
  const auto count_missed = [&] {
    size_t missed = 0;
    for (size_t v = 0; v < views.size(); ++v)
      missed += static_cast<size_t>(cv::countNonZero(sets[v].inner & ~rendered[v]));
    return missed;
  };
  const auto finish = [&] {
    stats.missed_after = count_missed();
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  };
  stats.missed_before = count_missed();
  if (stats.missed_before == 0) return finish();
  const GrownSilhouettes grown = GrowSilhouettes(views, options.margin_px);
  // The outer pixels are those the margin's growth does not reach.
  for (size_t v = 0; v < views.size(); ++v)
    sets[v].outer = ~grown.grown[v];
  // A vertex whose move was undone is not moved again.
  std::vector<uint8_t> frozen(mesh->vertices.size(), 0);
  const std::vector<Eigen::Vector3f> starts = mesh->vertices;
  for (int round = 0; round < options.rounds; ++round) {
    std::vector<uint8_t> taken = frozen;
    std::vector<Move> moves;
    size_t coverable = 0;
    for (size_t v = 0; v < views.size(); ++v) {
      const cv::Mat missed = sets[v].inner & ~rendered[v];
      if (cv::countNonZero(missed) == 0) continue;
      coverable +=
          ProposeMoves(views, grown, v, missed, *mesh, starts, footprint, options, taken, moves);
    }
    if (round == 0) stats.coverable_before = coverable;
    if (moves.empty()) break;
    ++stats.rounds;
    for (const Move& m : moves)
      mesh->vertices[static_cast<size_t>(m.vertex)] = m.to;
    std::vector<uint8_t> undone;
    std::vector<cv::Mat> after = UndoHarmfulMoves(views, sets, grown.projections, rendered, moves,
                                                  options.threads, mesh, &undone);
    size_t kept = 0;
    for (size_t k = 0; k < moves.size(); ++k) {
      if (undone[k] != 0)
        frozen[static_cast<size_t>(moves[k].vertex)] = 1;
      else
        ++kept;
    }
    stats.moved += kept;
    stats.undone += moves.size() - kept;
    rendered = std::move(after);
    if (kept == 0) break;
  }
  return finish();
}

}  // namespace silnet::aggregator
