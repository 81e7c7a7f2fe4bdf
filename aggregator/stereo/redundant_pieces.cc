#include "aggregator/stereo/redundant_pieces.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <numeric>
#include <tuple>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/mesh_topology.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// One inner pixel a piece covers that the body does not.
struct PieceMark {
  int32_t piece;
  uint32_t view;
  uint32_t pixel;  // y * width + x
};

// The pixels of one view the triangles `by_piece` (grouped by piece, the body's left out) cover
// among the inner pixels the body misses (`body_covered`): one mark per piece and pixel, and
// per pixel how many pieces cover it.
void MarkView(const StereoView& view, const TriangleMesh& mesh, const std::vector<int32_t>& piece,
              const std::vector<size_t>& by_piece, const cv::Mat& body_covered, double margin_px,
              uint32_t v, std::vector<PieceMark>* marks, std::vector<uint16_t>* count) {
  const cv::Mat inner = InnerSilhouettePixels(view.mask, margin_px);
  const int width = view.camera.width, height = view.camera.height;
  count->assign(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
  std::vector<int32_t> last(count->size(), -1);
  const auto project = [&](int32_t index) {
    return view.camera.Project(mesh.vertices[static_cast<size_t>(index)].cast<double>());
  };
  for (size_t t : by_piece) {
    const int32_t p = piece[t];
    const auto& tri = mesh.triangles[t];
    const auto a = project(tri[0]), b = project(tri[1]), c = project(tri[2]);
    if (!a || !b || !c) continue;
    ForEachPixelInTriangle(*a, *b, *c, width, height, [&](int x, int y) {
      if (inner.at<uint8_t>(y, x) == 0 || body_covered.at<uint8_t>(y, x) != 0) return;
      const auto pixel = static_cast<uint32_t>(y * width + x);
      if (last[pixel] == p) return;
      last[pixel] = p;
      ++(*count)[pixel];
      marks->push_back({p, v, pixel});
    });
  }
}

// `mesh` without the triangles of the pieces `remove` flags and the vertices left unused.
void DropPieces(const std::vector<int32_t>& piece, const std::vector<uint8_t>& remove,
                TriangleMesh* mesh) {
  std::vector<std::array<int32_t, 3>> kept;
  kept.reserve(mesh->triangles.size());
  std::vector<int32_t> new_index(mesh->vertices.size(), -1);
  for (size_t t = 0; t < mesh->triangles.size(); ++t) {
    if (piece[t] >= 0 && remove[static_cast<size_t>(piece[t])] != 0) continue;
    kept.push_back(mesh->triangles[t]);
    for (int32_t v : mesh->triangles[t])
      new_index[static_cast<size_t>(v)] = 0;
  }
  std::vector<Eigen::Vector3f> vertices;
  for (size_t v = 0; v < mesh->vertices.size(); ++v) {
    if (new_index[v] < 0) continue;
    new_index[v] = static_cast<int32_t>(vertices.size());
    vertices.push_back(mesh->vertices[v]);
  }
  for (auto& t : kept)
    for (int32_t& v : t)
      v = new_index[static_cast<size_t>(v)];
  mesh->vertices = std::move(vertices);
  mesh->triangles = std::move(kept);
}

}  // namespace

RedundantPieceStats RemoveRedundantPieces(const std::vector<StereoView>& views, TriangleMesh* mesh,
                                          double margin_px, int threads) {
  SILNET_CHECK(mesh != nullptr);
  SILNET_CHECK_MSG(margin_px >= 0, "the silhouette margin must be >= 0");
  const auto start = std::chrono::steady_clock::now();
  RedundantPieceStats stats;
  const std::vector<int32_t> piece = TrianglePieces(*mesh, &stats.pieces_before);
  if (stats.pieces_before < 2) return stats;
  std::vector<size_t> size(stats.pieces_before, 0);
  for (int32_t p : piece)
    if (p >= 0) ++size[static_cast<size_t>(p)];
  const auto body = static_cast<int32_t>(std::max_element(size.begin(), size.end()) - size.begin());
  // The triangles grouped by piece, so each piece is drawn in one go.
  std::vector<size_t> by_piece;
  for (size_t t = 0; t < piece.size(); ++t)
    if (piece[t] >= 0 && piece[t] != body) by_piece.push_back(t);
  std::stable_sort(by_piece.begin(), by_piece.end(),
                   [&piece](size_t a, size_t b) { return piece[a] < piece[b]; });
  TriangleMesh body_mesh;
  body_mesh.vertices = mesh->vertices;
  for (size_t t = 0; t < piece.size(); ++t)
    if (piece[t] == body) body_mesh.triangles.push_back(mesh->triangles[t]);

  std::vector<std::vector<PieceMark>> marks(views.size());
  std::vector<std::vector<uint16_t>> count(views.size());
  ParallelFor(views.size(), threads, [&](size_t v) {
    const cv::Mat body_covered = RenderMeshSilhouette(body_mesh, views[v].camera);
    MarkView(views[v], *mesh, piece, by_piece, body_covered, margin_px, static_cast<uint32_t>(v),
             &marks[v], &count[v]);
  });
  std::vector<PieceMark> all;
  for (const auto& m : marks)
    all.insert(all.end(), m.begin(), m.end());
  std::sort(all.begin(), all.end(), [](const PieceMark& a, const PieceMark& b) {
    return std::tie(a.piece, a.view, a.pixel) < std::tie(b.piece, b.view, b.pixel);
  });
  // Where each piece's marks begin in `all`.
  std::vector<size_t> first(stats.pieces_before + 1, 0);
  for (const PieceMark& m : all)
    ++first[static_cast<size_t>(m.piece) + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());

  std::vector<size_t> order(stats.pieces_before);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&size](size_t a, size_t b) { return size[a] < size[b]; });
  std::vector<uint8_t> remove(stats.pieces_before, 0);
  for (size_t p : order) {
    if (static_cast<int32_t>(p) == body) continue;
    const auto needed = [&](const PieceMark& m) { return count[m.view][m.pixel] < 2; };
    if (std::any_of(all.begin() + static_cast<long>(first[p]),
                    all.begin() + static_cast<long>(first[p + 1]), needed))
      continue;
    for (size_t i = first[p]; i < first[p + 1]; ++i)
      --count[all[i].view][all[i].pixel];
    remove[p] = 1;
    ++stats.removed;
    stats.triangles_removed += size[p];
  }
  if (stats.removed > 0) DropPieces(piece, remove, mesh);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace silnet::aggregator
