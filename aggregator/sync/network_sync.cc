#include "aggregator/sync/network_sync.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// The measurement of `edge` oriented away from camera `from`: o_from - o_other.
double OffsetFrom(const OffsetEdge& edge, size_t from) {
  return edge.i == from ? edge.offset : -edge.offset;
}

double Square(double x) {
  return x * x;
}

void CheckInput(size_t cameras, const std::vector<OffsetEdge>& edges, const SyncOptions& options) {
  SILNET_CHECK(options.cycle_sigmas > 0.0);
  SILNET_CHECK(options.cycle_min_frames >= 0.0);
  SILNET_CHECK(options.outlier_fraction >= 0.0 && options.outlier_fraction <= 1.0);
  SILNET_CHECK(options.residual_sigmas > 0.0);
  for (size_t e = 0; e < edges.size(); ++e) {
    const OffsetEdge& edge = edges[e];
    SILNET_CHECK_MSG(edge.i < cameras && edge.j < cameras, "edge " << e << " joins cameras "
                                                                   << edge.i << " and " << edge.j
                                                                   << " of " << cameras);
    SILNET_CHECK_MSG(edge.i != edge.j, "edge " << e << " joins camera " << edge.i << " to itself");
    SILNET_CHECK_MSG(std::isfinite(edge.offset), "edge " << e << " has offset " << edge.offset);
    SILNET_CHECK_MSG(edge.sigma > 0.0 && std::isfinite(edge.sigma),
                     "edge " << e << " has sigma " << edge.sigma);
  }
}

// The edges still in play, by camera and neighbour; parallel edges stay separate.
class EdgeGraph {
 public:
  using Links = std::map<size_t, std::vector<size_t>>;  // neighbour -> edges to it

  EdgeGraph(size_t cameras, const std::vector<OffsetEdge>& edges)
      : edges_(edges), links_(cameras), active_(edges.size(), true) {
    for (size_t e = 0; e < edges.size(); ++e) {
      links_[edges[e].i][edges[e].j].push_back(e);
      links_[edges[e].j][edges[e].i].push_back(e);
    }
  }

  bool active(size_t e) const { return active_[e]; }
  const Links& links(size_t camera) const { return links_[camera]; }

  // Active edges between cameras a and b, or null when there are none.
  const std::vector<size_t>* Between(size_t a, size_t b) const {
    const auto it = links_[a].find(b);
    return it == links_[a].end() ? nullptr : &it->second;
  }

  void Remove(size_t e) {
    active_[e] = false;
    Unlink(edges_[e].i, edges_[e].j, e);
    Unlink(edges_[e].j, edges_[e].i, e);
  }

  // Whether removing edge e would separate its cameras.
  bool IsBridge(size_t e) const {
    std::vector<bool> seen(links_.size(), false);
    std::vector<size_t> stack = {edges_[e].i};
    seen[edges_[e].i] = true;
    while (!stack.empty()) {
      const size_t camera = stack.back();
      stack.pop_back();
      for (const auto& [neighbour, via] : links_[camera]) {
        const bool only_e = via.size() == 1 && via[0] == e;
        if (seen[neighbour] || only_e) continue;
        seen[neighbour] = true;
        stack.push_back(neighbour);
      }
    }
    return !seen[edges_[e].j];
  }

 private:
  void Unlink(size_t a, size_t b, size_t e) {
    std::vector<size_t>& via = links_[a][b];
    via.erase(std::find(via.begin(), via.end(), e));
    if (via.empty()) links_[a].erase(b);
  }

  const std::vector<OffsetEdge>& edges_;
  std::vector<Links> links_;
  std::vector<bool> active_;
};

// The triangle cycles through one edge.
struct CycleStats {
  size_t cycles = 0;
  size_t failed = 0;
  // Mean over the cycles of the misclosure share that a cycle's own adjustment gives this edge,
  // in this edge's sigmas (|sum| * sigma_e / sum of variances); breaks ties between edges.
  double share = 0.0;

  bool Outlier(double fraction) const {
    return failed > 0 && static_cast<double>(failed) > fraction * static_cast<double>(cycles);
  }
};

// Whether edge statistics `a` are worse than `b`: failed fraction, failed count, then share.
bool Worse(const CycleStats& a, const CycleStats& b) {
  const size_t a_fraction = a.failed * b.cycles, b_fraction = b.failed * a.cycles;
  if (a_fraction != b_fraction) return a_fraction > b_fraction;
  if (a.failed != b.failed) return a.failed > b.failed;
  return a.share > b.share;
}

CycleStats EvaluateCycles(const std::vector<OffsetEdge>& edges, const EdgeGraph& graph, size_t e,
                          const SyncOptions& options) {
  const OffsetEdge& edge = edges[e];
  CycleStats stats;
  // Cycles i -> j -> k -> i, one per pair of active edges j-k and k-i.
  for (const auto& [k, jk] : graph.links(edge.j)) {
    const std::vector<size_t>* ki = k == edge.i ? nullptr : graph.Between(k, edge.i);
    if (ki == nullptr) continue;
    for (size_t f : jk) {
      for (size_t g : *ki) {
        const double sum = edge.offset + OffsetFrom(edges[f], edge.j) + OffsetFrom(edges[g], k);
        const double variance =
            Square(edge.sigma) + Square(edges[f].sigma) + Square(edges[g].sigma);
        const double limit =
            std::max(options.cycle_sigmas * std::sqrt(variance), options.cycle_min_frames);
        ++stats.cycles;
        if (std::abs(sum) > limit) ++stats.failed;
        stats.share += std::abs(sum) * edge.sigma / variance;
      }
    }
  }
  if (stats.cycles > 0) stats.share /= static_cast<double>(stats.cycles);
  return stats;
}

void Reject(SyncEdgeResult& result, EdgeGraph& graph, size_t e, std::string reason) {
  result.rejection = std::move(reason);
  graph.Remove(e);
}

// The active edges that share a triangle with edge w: their cycle counts change without it.
std::vector<size_t> TriangleNeighbours(const std::vector<OffsetEdge>& edges, const EdgeGraph& graph,
                                       size_t w) {
  const size_t i = edges[w].i, j = edges[w].j;
  std::vector<size_t> neighbours;
  for (const auto& [k, ik] : graph.links(i)) {
    const std::vector<size_t>* jk = k == j ? nullptr : graph.Between(j, k);
    if (jk == nullptr) continue;
    neighbours.insert(neighbours.end(), ik.begin(), ik.end());
    neighbours.insert(neighbours.end(), jk->begin(), jk->end());
  }
  return neighbours;
}

// The cycle test's state: the current statistics of each edge and whether its last
// evaluation that found any cycles flagged it as an outlier.
struct CycleRecord {
  std::vector<CycleStats> stats;
  std::vector<bool> flagged;

  void Update(size_t e, const CycleStats& latest, double outlier_fraction,
              std::vector<SyncEdgeResult>& results) {
    stats[e] = latest;
    if (latest.cycles == 0) return;
    results[e].cycles = latest.cycles;
    results[e].cycles_failed = latest.failed;
    flagged[e] = latest.Outlier(outlier_fraction);
  }
};

// Rejects edge w and re-evaluates the edges that shared a triangle with it. A flagged edge
// left without cycles is cleared when w had the stronger evidence (more failed cycles), but
// rejected with w when the two are tied: nothing is left to tell which is wrong (e.g. the two
// links of a camera whose only triangle fails).
void RemoveOutlier(const std::vector<OffsetEdge>& edges, const SyncOptions& options, size_t w,
                   EdgeGraph& graph, CycleRecord& record, std::vector<SyncEdgeResult>& results) {
  const CycleStats removed = record.stats[w];
  const std::vector<size_t> affected = TriangleNeighbours(edges, graph, w);
  Reject(
      results[w], graph, w,
      fmt::format("cycle test: {} of {} triangles fail to close", removed.failed, removed.cycles));
  for (size_t e : affected) {
    const CycleStats before = record.stats[e];
    record.Update(e, EvaluateCycles(edges, graph, e, options), options.outlier_fraction, results);
    if (record.stats[e].cycles > 0 || !record.flagged[e]) continue;
    record.flagged[e] = false;
    if (before.cycles != removed.cycles || before.failed != removed.failed) continue;
    Reject(results[e], graph, e,
           fmt::format("cycle test: {} of {} triangles fail to close, as for the rejected edge "
                       "{}-{}, and no triangle is left to tell which is wrong",
                       before.failed, before.cycles, edges[w].i, edges[w].j));
  }
}

// Removes the worst outlier edge until none is left.
void RunCycleTest(const std::vector<OffsetEdge>& edges, const SyncOptions& options,
                  EdgeGraph& graph, std::vector<SyncEdgeResult>& results) {
  CycleRecord record{std::vector<CycleStats>(edges.size()), std::vector<bool>(edges.size())};
  for (size_t e = 0; e < edges.size(); ++e) {
    record.Update(e, EvaluateCycles(edges, graph, e, options), options.outlier_fraction, results);
  }
  while (true) {
    std::optional<size_t> worst;
    for (size_t e = 0; e < edges.size(); ++e) {
      const bool outlier = graph.active(e) && record.stats[e].Outlier(options.outlier_fraction);
      if (outlier && (!worst || Worse(record.stats[e], record.stats[*worst]))) worst = e;
    }
    if (!worst) return;
    RemoveOutlier(edges, options, *worst, graph, record, results);
  }
}

// Connected components of the active edges, labelled 0, 1, ... in order of their lowest camera.
std::vector<size_t> Components(const EdgeGraph& graph, size_t cameras) {
  constexpr size_t kUnset = static_cast<size_t>(-1);
  std::vector<size_t> label(cameras, kUnset);
  size_t next = 0;
  for (size_t start = 0; start < cameras; ++start) {
    if (label[start] != kUnset) continue;
    std::vector<size_t> stack = {start};
    label[start] = next;
    while (!stack.empty()) {
      const size_t camera = stack.back();
      stack.pop_back();
      for (const auto& link : graph.links(camera)) {
        if (label[link.first] != kUnset) continue;
        label[link.first] = next;
        stack.push_back(link.first);
      }
    }
    ++next;
  }
  return label;
}

// The label of the largest component, the lowest-labelled one on a tie.
size_t LargestComponent(const std::vector<size_t>& label) {
  std::vector<size_t> size;
  for (size_t l : label) {
    if (l >= size.size()) size.resize(l + 1, 0);
    ++size[l];
  }
  return static_cast<size_t>(std::max_element(size.begin(), size.end()) - size.begin());
}

// Picks the reference, the lowest camera of the largest component, and marks that component's
// cameras synchronised; the active edges of other components get their rejection.
void ChooseReference(const std::vector<OffsetEdge>& edges, const EdgeGraph& graph,
                     const std::vector<size_t>& label, SyncResult& sync) {
  const size_t largest = LargestComponent(label);
  sync.reference =
      static_cast<size_t>(std::find(label.begin(), label.end(), largest) - label.begin());
  sync.synchronised.resize(label.size());
  for (size_t c = 0; c < label.size(); ++c) {
    sync.synchronised[c] = label[c] == largest;
  }
  for (size_t e = 0; e < edges.size(); ++e) {
    if (graph.active(e) && !sync.synchronised[edges[e].i]) {
      sync.edges[e].rejection =
          fmt::format("not connected to the reference's component (camera {})", sync.reference);
    }
  }
}

struct Solution {
  std::vector<double> offsets;  // per camera; 0 outside the component
  std::vector<double> sigmas;
};

// Weighted least squares over the active edges of the reference's component (`member`), with
// the reference fixed at 0: normal equations (J^T W J) x = J^T W m, covariance (J^T W J)^-1.
Solution Solve(const std::vector<OffsetEdge>& edges, const EdgeGraph& graph,
               const std::vector<bool>& member, size_t reference) {
  const size_t cameras = member.size();
  std::vector<Eigen::Index> unknown(cameras, -1);
  Eigen::Index n = 0;
  for (size_t c = 0; c < cameras; ++c) {
    if (member[c] && c != reference) unknown[c] = n++;
  }
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (size_t e = 0; e < edges.size(); ++e) {
    const OffsetEdge& edge = edges[e];
    if (!graph.active(e) || !member[edge.i]) continue;
    const double weight = 1.0 / Square(edge.sigma);
    const Eigen::Index a = unknown[edge.i], b = unknown[edge.j];  // row: o_i - o_j = offset
    if (a >= 0) {
      normal(a, a) += weight;
      rhs(a) += weight * edge.offset;
    }
    if (b >= 0) {
      normal(b, b) += weight;
      rhs(b) -= weight * edge.offset;
    }
    if (a >= 0 && b >= 0) {
      normal(a, b) -= weight;
      normal(b, a) -= weight;
    }
  }
  Solution solution{std::vector<double>(cameras, 0.0), std::vector<double>(cameras, 0.0)};
  if (n == 0) return solution;
  const Eigen::LLT<Eigen::MatrixXd> llt(normal);
  SILNET_CHECK_MSG(llt.info() == Eigen::Success, "normal equations of a connected component");
  const Eigen::VectorXd x = llt.solve(rhs);
  const Eigen::MatrixXd covariance = llt.solve(Eigen::MatrixXd::Identity(n, n));
  for (size_t c = 0; c < cameras; ++c) {
    if (unknown[c] < 0) continue;
    solution.offsets[c] = x(unknown[c]);
    solution.sigmas[c] = std::sqrt(covariance(unknown[c], unknown[c]));
  }
  return solution;
}

double Residual(const OffsetEdge& edge, const std::vector<double>& offsets) {
  return edge.offset - (offsets[edge.i] - offsets[edge.j]);
}

// Solves, removes the edge with the largest residual in sigmas beyond the limits, and solves
// again until none is left. A bridge is never removed; its residual is zero in exact
// arithmetic anyway, so this only guards against rounding.
Solution RunResidualCheck(const std::vector<OffsetEdge>& edges, const SyncOptions& options,
                          const std::vector<bool>& member, size_t reference, EdgeGraph& graph,
                          std::vector<SyncEdgeResult>& results) {
  while (true) {
    Solution solution = Solve(edges, graph, member, reference);
    std::vector<std::pair<double, size_t>> excess;  // (|residual| / sigma, edge)
    for (size_t e = 0; e < edges.size(); ++e) {
      const OffsetEdge& edge = edges[e];
      if (!graph.active(e) || !member[edge.i]) continue;
      const double residual = std::abs(Residual(edge, solution.offsets));
      if (residual > std::max(options.residual_sigmas * edge.sigma, options.cycle_min_frames)) {
        excess.emplace_back(residual / edge.sigma, e);
      }
    }
    std::sort(excess.begin(), excess.end(), std::greater<>());
    const auto removable = std::find_if(excess.begin(), excess.end(),
                                        [&](const auto& x) { return !graph.IsBridge(x.second); });
    if (removable == excess.end()) return solution;
    const size_t e = removable->second;
    Reject(results[e], graph, e,
           fmt::format("residual check: {:.2f} frames ({:.1f} sigma) from the least-squares "
                       "solution",
                       Residual(edges[e], solution.offsets), removable->first));
  }
}

// Why `camera`, outside the reference's component, could not be synchronised.
std::string UnsynchronisedReason(size_t camera, const std::vector<OffsetEdge>& edges,
                                 const EdgeGraph& graph, const std::vector<size_t>& label,
                                 size_t reference) {
  size_t links = 0;
  bool rejected_link = false;  // a rejected edge joins this component to the reference's
  for (const OffsetEdge& edge : edges) {
    if (edge.i == camera || edge.j == camera) ++links;
    const bool here_i = label[edge.i] == label[camera], here_j = label[edge.j] == label[camera];
    const bool ref_i = label[edge.i] == label[reference], ref_j = label[edge.j] == label[reference];
    if ((here_i && ref_j) || (here_j && ref_i)) rejected_link = true;
  }
  if (links == 0) return fmt::format("camera {} has no offset measurements", camera);
  if (graph.links(camera).empty()) {
    return links == 1
               ? fmt::format("the only link of camera {} was rejected as an outlier", camera)
               : fmt::format("all {} links of camera {} were rejected as outliers", links, camera);
  }
  if (rejected_link) {
    return fmt::format(
        "the links between camera {}'s component and the reference's component (camera {}) were "
        "rejected as outliers",
        camera, reference);
  }
  return fmt::format(
      "no offset measurement links camera {} to the reference's component (camera {})", camera,
      reference);
}

// Residuals of all edges between synchronised cameras; RMS over the used ones.
void FillResiduals(const std::vector<OffsetEdge>& edges, SyncResult& sync) {
  double sum = 0.0, sum_normalised = 0.0;
  size_t used = 0;
  for (size_t e = 0; e < edges.size(); ++e) {
    SyncEdgeResult& result = sync.edges[e];
    if (!sync.synchronised[edges[e].i] || !sync.synchronised[edges[e].j]) continue;
    result.residual = Residual(edges[e], sync.offsets);
    if (!result.used) continue;
    sum += Square(result.residual);
    sum_normalised += Square(result.residual / edges[e].sigma);
    ++used;
  }
  if (used == 0) return;
  sync.rms_residual = std::sqrt(sum / static_cast<double>(used));
  sync.rms_normalised = std::sqrt(sum_normalised / static_cast<double>(used));
}

}  // namespace

SyncResult SynchroniseNetwork(size_t cameras, const std::vector<OffsetEdge>& edges,
                              const SyncOptions& options) {
  CheckInput(cameras, edges, options);
  SyncResult sync;
  sync.edges.resize(edges.size());
  for (size_t e = 0; e < edges.size(); ++e) {
    sync.edges[e].edge = edges[e];
  }
  if (cameras == 0) return sync;

  EdgeGraph graph(cameras, edges);
  RunCycleTest(edges, options, graph, sync.edges);
  const std::vector<size_t> label = Components(graph, cameras);
  ChooseReference(edges, graph, label, sync);
  const Solution solution =
      RunResidualCheck(edges, options, sync.synchronised, sync.reference, graph, sync.edges);
  sync.offsets = solution.offsets;
  sync.sigmas = solution.sigmas;
  sync.reasons.resize(cameras);
  for (size_t c = 0; c < cameras; ++c) {
    if (!sync.synchronised[c]) {
      sync.reasons[c] = UnsynchronisedReason(c, edges, graph, label, sync.reference);
    }
  }
  for (size_t e = 0; e < edges.size(); ++e) {
    sync.edges[e].used = graph.active(e) && sync.synchronised[edges[e].i];
  }
  FillResiduals(edges, sync);
  return sync;
}

}  // namespace silnet::aggregator
