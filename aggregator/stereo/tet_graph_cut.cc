#include "aggregator/stereo/tet_graph_cut.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "aggregator/stereo/max_flow.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {

struct TetGraphCut::Graph {
  MaxFlowGraph flow{0, 0};
  std::vector<CellFace> faces;  // sorted
};

TetGraphCut::~TetGraphCut() = default;

const std::vector<CellFace>& TetGraphCut::Faces() const {
  return graph_->faces;
}

double TetGraphCut::flow() const {
  return graph_->flow.flow();
}

bool TetGraphCutOptions::IsValid(std::string* reason) const {
  const auto fail = [&](const char* why) {
    if (reason) *reason = why;
    return false;
  };
  if (!(lambda >= 0)) return fail("lambda must be >= 0");
  if (!(sigma > 0)) return fail("sigma must be positive");
  if (!(ballooning >= 0)) return fail("ballooning must be >= 0");
  if (!(patch_prefilter < 1)) return fail("patch_prefilter must be below 1");
  return true;
}

TetGraphCut::TetGraphCut(const TetMesh& mesh, std::vector<CellFace> faces_of_mesh,
                         const std::vector<CellLabel>& labels, const std::vector<uint32_t>& votes,
                         const PatchScorer& scorer, double footprint,
                         const TetGraphCutOptions& options, const Progress* cancel)
    : mesh_(mesh), graph_(std::make_unique<Graph>()) {
  SILNET_CHECK(labels.size() == mesh.tetrahedra.size());
  SILNET_CHECK(votes.empty() || votes.size() == mesh.tetrahedra.size());
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  SILNET_CHECK(footprint > 0);
  const size_t cells = mesh.tetrahedra.size();
  SILNET_CHECK(faces_of_mesh.size() == 4 * cells);
  graph_->faces = std::move(faces_of_mesh);
  const std::vector<CellFace>& faces = graph_->faces;
  // Shared faces: consecutive entries with equal ids.
  std::vector<size_t> shared;
  for (size_t k = 0; k + 1 < faces.size(); ++k)
    if (faces[k].ids == faces[k + 1].ids) shared.push_back(k);

  // Face costs, scored where the cut may pass.
  const double max_edge = options.max_scored_face_footprints * footprint;
  std::vector<double> capacity(shared.size(), 0.0);
  std::vector<uint8_t> scored(shared.size(), 0);
  ParallelFor(shared.size(), options.threads, cancel, [&](size_t s) {
    const CellFace& f = faces[shared[s]];
    const CellLabel la = labels[static_cast<size_t>(f.cell)];
    const CellLabel lb = labels[static_cast<size_t>(faces[shared[s] + 1].cell)];
    const Eigen::Vector3d& a = mesh.vertices[f.ids[0]];
    const Eigen::Vector3d& b = mesh.vertices[f.ids[1]];
    const Eigen::Vector3d& c = mesh.vertices[f.ids[2]];
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double area = 0.5 * cross.norm();
    double w = 0.0;
    const bool free_side = la == CellLabel::kFree || lb == CellLabel::kFree;
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    if (free_side && longest <= max_edge) {
      const Eigen::Vector3d n = cross.normalized();
      const Eigen::Vector3d u = (b - a).normalized();
      const Eigen::Vector3d v = n.cross(u);
      const Eigen::Vector3d centre = (a + b + c) / 3;
      const float score =
          scorer.PlaneEitherSide(centre, n, u, v, footprint, options.patch_prefilter).score;
      w = std::clamp(static_cast<double>(score), 0.0, 1.0);
      scored[s] = 1;
    }
    const double t = std::tan(std::numbers::pi / 2 * (w - 1));
    const double photo = w <= 0 ? 1.0 : 1 - std::exp(-t * t / (options.sigma * options.sigma));
    capacity[s] = (photo + options.lambda) * area;
  });
  interior_.assign(cells, 0);
  forced_side_.assign(cells, 0);
  if (cancel && cancel->cancelled()) {
    cancelled_ = true;
    return;
  }

  MaxFlowGraph& graph = graph_->flow;
  graph = MaxFlowGraph(static_cast<int64_t>(cells), static_cast<int64_t>(shared.size()));
  graph.AddNodes(static_cast<int>(cells));
  double total = 1.0;
  for (double c : capacity)
    total += c;
  const double balloon = options.ballooning / footprint;
  for (size_t t = 0; t < cells; ++t) {
    if (balloon > 0 && labels[t] == CellLabel::kFree &&
        (votes.empty() || votes[t] < options.ballooning_max_votes)) {
      const Tetrahedron& q = mesh.tetrahedra[t];
      const auto& x = mesh.vertices;
      const double volume = std::abs(SignedVolume6(x[q[0]], x[q[1]], x[q[2]], x[q[3]])) / 6;
      graph.AddTerminalCapacities(static_cast<int>(t), balloon * volume, 0);
    }
    if (labels[t] == CellLabel::kInterior)
      graph.AddTerminalCapacities(static_cast<int>(t), total, 0);
    if (labels[t] == CellLabel::kExterior)
      graph.AddTerminalCapacities(static_cast<int>(t), 0, total);
  }
  for (size_t s = 0; s < shared.size(); ++s) {
    const int a = faces[shared[s]].cell, b = faces[shared[s] + 1].cell;
    graph.AddEdge(a, b, capacity[s], capacity[s]);
    faces_scored_ += scored[s];
  }
  graph.Solve();
  links_ = shared.size();
  for (size_t t = 0; t < cells; ++t)
    interior_[t] = graph.IsSourceSide(static_cast<int>(t)) ? 1 : 0;
}

size_t TetGraphCut::ForceInterior(const std::vector<int32_t>& cells) {
  return Force(cells, true);
}

size_t TetGraphCut::ForceExterior(const std::vector<int32_t>& cells) {
  return Force(cells, false);
}

size_t TetGraphCut::Force(const std::vector<int32_t>& cells, bool interior) {
  SILNET_CHECK_MSG(!cancelled_, "a cancelled cut cannot be forced");
  size_t changed = 0;
  for (int32_t c : cells) {
    const auto t = static_cast<size_t>(c);
    if (forced_side_[t] != 0 || (interior_[t] != 0) == interior) continue;
    if (interior)
      graph_->flow.ForceSourceSide(c);
    else
      graph_->flow.ForceSinkSide(c);
    forced_side_[t] = interior ? 1 : 2;
    ++changed;
  }
  if (changed == 0) return 0;
  graph_->flow.Resolve();
  for (size_t t = 0; t < interior_.size(); ++t)
    interior_[t] = graph_->flow.IsSourceSide(static_cast<int>(t)) ? 1 : 0;
  return changed;
}

std::vector<int32_t> TetGraphCut::Forced() const {
  std::vector<int32_t> cells;
  for (size_t t = 0; t < forced_side_.size(); ++t)
    if (forced_side_[t] == 1) cells.push_back(static_cast<int32_t>(t));
  return cells;
}

TriangleMesh TetGraphCut::Surface() const {
  return InteriorBoundary(mesh_, graph_->faces, interior_);
}

}  // namespace silnet::aggregator
