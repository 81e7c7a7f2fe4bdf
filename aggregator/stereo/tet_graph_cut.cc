#include "aggregator/stereo/tet_graph_cut.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "aggregator/hulls/morton_order.h"
#include "aggregator/stereo/max_flow.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {

struct TetGraphCut::Graph {
  MaxFlowGraph flow{0, 0};
  std::vector<CellFace> faces;  // sorted
  std::vector<int32_t> node;    // per cell, its node in the flow graph
  // The ballooning's source links: node, capacity at the options' weight.
  std::vector<std::pair<int32_t, double>> ballooning;
};

namespace {

// Per cell, its node: the cells not labelled exterior numbered in the Z-order of their
// centroids, so cells near in space get near node ids and the max-flow's searches touch memory
// near what they touched last; -1 for the exterior ones (merged into the sink).
std::vector<int32_t> SpatialNodeOrder(const TetMesh& mesh, const std::vector<CellLabel>& labels) {
  std::vector<Eigen::Vector3d> centres;
  std::vector<int32_t> cells;  // centres[k] is cell cells[k]'s
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    if (labels[t] == CellLabel::kExterior) continue;
    const Tetrahedron& q = mesh.tetrahedra[t];
    centres.push_back(
        (mesh.vertices[q[0]] + mesh.vertices[q[1]] + mesh.vertices[q[2]] + mesh.vertices[q[3]]) /
        4);
    cells.push_back(static_cast<int32_t>(t));
  }
  const std::vector<uint32_t> order = MortonCurve(mesh.vertices).Order(centres);
  std::vector<int32_t> node(mesh.tetrahedra.size(), -1);
  for (size_t r = 0; r < order.size(); ++r)
    node[static_cast<size_t>(cells[order[r]])] = static_cast<int32_t>(r);
  return node;
}

}  // namespace

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

  const auto flow_start = std::chrono::steady_clock::now();
  // Exterior cells are merged into the sink: a face between one and a cell of the graph is
  // that cell's sink link, faces between two are left out.
  graph_->node = SpatialNodeOrder(mesh, labels);
  const std::vector<int32_t>& node = graph_->node;
  const auto nodes =
      static_cast<int>(std::count_if(node.begin(), node.end(), [](int32_t n) { return n >= 0; }));
  MaxFlowGraph& graph = graph_->flow;
  graph = MaxFlowGraph(nodes, static_cast<int64_t>(shared.size()));
  if (nodes > 0) graph.AddNodes(nodes);
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
      graph.AddTerminalCapacities(node[t], balloon * volume, 0);
      graph_->ballooning.emplace_back(node[t], balloon * volume);
    }
    if (labels[t] == CellLabel::kInterior) graph.AddTerminalCapacities(node[t], total, 0);
  }
  // The n-links in node order (each from its lower node), so a node's arcs lie near its
  // neighbours' in the library's arc blocks.
  std::vector<std::pair<int32_t, uint32_t>> by_node;
  by_node.reserve(shared.size());
  for (size_t s = 0; s < shared.size(); ++s) {
    faces_scored_ += scored[s];
    const int32_t a = node[static_cast<size_t>(faces[shared[s]].cell)];
    const int32_t b = node[static_cast<size_t>(faces[shared[s] + 1].cell)];
    if (a >= 0 && b >= 0)
      by_node.emplace_back(std::min(a, b), static_cast<uint32_t>(s));
    else if (a >= 0 || b >= 0)
      graph.AddTerminalCapacities(std::max(a, b), 0, capacity[s]);
  }
  std::sort(by_node.begin(), by_node.end());
  for (const auto& [lower, s] : by_node) {
    graph.AddEdge(node[static_cast<size_t>(faces[shared[s]].cell)],
                  node[static_cast<size_t>(faces[shared[s] + 1].cell)], capacity[s], capacity[s]);
  }
  graph.Solve();
  seconds_max_flow_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - flow_start).count();
  links_ = shared.size();
  ReadSides();
}

void TetGraphCut::ReadSides() {
  for (size_t t = 0; t < interior_.size(); ++t) {
    const int32_t n = graph_->node[t];
    interior_[t] = n >= 0 && graph_->flow.IsSourceSide(n) ? 1 : 0;
  }
}

size_t TetGraphCut::RaiseBallooning(double factor) {
  SILNET_CHECK_MSG(!cancelled_, "a cancelled cut cannot be changed");
  SILNET_CHECK_MSG(factor >= 1, "the ballooning can only be raised");
  SILNET_CHECK_MSG(std::none_of(forced_side_.begin(), forced_side_.end(),
                                [](uint8_t side) { return side != 0; }),
                   "the ballooning is raised before any cell is forced");
  if (factor == 1 || graph_->ballooning.empty()) return 0;
  for (const auto& [n, capacity] : graph_->ballooning)
    graph_->flow.AddSourceCapacity(n, (factor - 1) * capacity);
  ballooning_factor_ *= factor;
  const std::vector<uint8_t> before = interior_;
  graph_->flow.Resolve();
  ReadSides();
  size_t gained = 0;
  for (size_t t = 0; t < interior_.size(); ++t)
    gained += interior_[t] > before[t] ? 1 : 0;
  return gained;
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
    // Cells merged into the sink are exterior for good.
    if (forced_side_[t] != 0 || (interior_[t] != 0) == interior || graph_->node[t] < 0) continue;
    if (interior)
      graph_->flow.ForceSourceSide(graph_->node[t]);
    else
      graph_->flow.ForceSinkSide(graph_->node[t]);
    forced_side_[t] = interior ? 1 : 2;
    ++changed;
  }
  if (changed == 0) return 0;
  graph_->flow.Resolve();
  ReadSides();
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
