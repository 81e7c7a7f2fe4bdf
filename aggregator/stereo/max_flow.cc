#include "aggregator/stereo/max_flow.h"

#include <maxflow.h>

#include <algorithm>
#include <limits>
#include <new>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using BkGraph = maxflow::Graph_DDD;

// The library reports allocation failures through this hook (its default calls exit()).
void ThrowOnLibraryError(const char* /*message*/) {
  throw std::bad_alloc();
}

// Sizes of the library's node and arc records for Graph<double, double, double> on a 64-bit
// build (three pointers plus counters and a double; three pointers plus a double).
constexpr size_t kNodeBytes = 48;
constexpr size_t kArcBytes = 32;

int ClampToInt(int64_t n) {
  return static_cast<int>(
      std::min<int64_t>(std::max<int64_t>(n, 0), std::numeric_limits<int>::max() / 2));
}

}  // namespace

struct MaxFlowGraph::Impl {
  Impl(int64_t expected_nodes, int64_t expected_edges)
      : graph(ClampToInt(expected_nodes), ClampToInt(expected_edges), &ThrowOnLibraryError) {}
  BkGraph graph;
  int nodes = 0;
  int64_t edges = 0;
  bool solved = false;
  bool pending = false;  // nodes changed since the last Solve() or Resolve()
  bool forced = false;   // a node was forced since Solve()
  double total = 0;      // sum of all capacities added (t-links and both arcs of n-links)
  double flow = 0;
};

MaxFlowGraph::MaxFlowGraph(int64_t expected_nodes, int64_t expected_edges)
    : impl_(std::make_unique<Impl>(expected_nodes, expected_edges)) {}

MaxFlowGraph::~MaxFlowGraph() = default;
MaxFlowGraph::MaxFlowGraph(MaxFlowGraph&&) noexcept = default;
MaxFlowGraph& MaxFlowGraph::operator=(MaxFlowGraph&&) noexcept = default;

int MaxFlowGraph::AddNodes(int count) {
  SILNET_CHECK(count > 0 && !impl_->solved);
  SILNET_CHECK_MSG(count <= std::numeric_limits<int>::max() - impl_->nodes,
                   "max-flow graph limited to 2^31 - 1 nodes");
  const int first = impl_->graph.add_node(count);
  impl_->nodes += count;
  return first;
}

void MaxFlowGraph::AddTerminalCapacities(int node, double source_capacity, double sink_capacity) {
  SILNET_CHECK(node >= 0 && node < impl_->nodes && !impl_->solved);
  SILNET_CHECK(source_capacity >= 0 && sink_capacity >= 0);
  impl_->graph.add_tweights(node, source_capacity, sink_capacity);
  impl_->total += source_capacity + sink_capacity;
}

void MaxFlowGraph::AddEdge(int a, int b, double a_to_b, double b_to_a) {
  SILNET_CHECK(a >= 0 && a < impl_->nodes && b >= 0 && b < impl_->nodes && a != b);
  SILNET_CHECK(a_to_b >= 0 && b_to_a >= 0 && !impl_->solved);
  impl_->graph.add_edge(a, b, a_to_b, b_to_a);
  impl_->total += a_to_b + b_to_a;
  ++impl_->edges;
}

double MaxFlowGraph::Solve() {
  SILNET_CHECK_MSG(!impl_->solved, "MaxFlowGraph::Solve called twice");
  impl_->flow = impl_->nodes > 0 ? impl_->graph.maxflow() : 0.0;
  impl_->solved = true;
  return impl_->flow;
}

void MaxFlowGraph::ForceSourceSide(int node) {
  Force(node, true);
}

void MaxFlowGraph::ForceSinkSide(int node) {
  Force(node, false);
}

void MaxFlowGraph::Force(int node, bool source) {
  SILNET_CHECK_MSG(impl_->solved, "MaxFlowGraph: forcing a node before Solve");
  SILNET_CHECK(node >= 0 && node < impl_->nodes);
  // A cut that cuts a forcing link costs more than all the original links together, so more
  // than the cut that separates only the forced nodes by their kind: no minimum cut does. The
  // library adds this to the node's residual capacity (cancelling the other side's as flow).
  const double capacity = impl_->total + 1.0;
  impl_->graph.add_tweights(node, source ? capacity : 0.0, source ? 0.0 : capacity);
  impl_->graph.mark_node(node);
  impl_->pending = true;
  impl_->forced = true;
}

void MaxFlowGraph::AddSourceCapacity(int node, double capacity) {
  SILNET_CHECK_MSG(impl_->solved && !impl_->forced,
                   "MaxFlowGraph: source capacity added before Solve or after forcing");
  SILNET_CHECK(node >= 0 && node < impl_->nodes && capacity >= 0);
  impl_->graph.add_tweights(node, capacity, 0.0);
  impl_->graph.mark_node(node);
  impl_->total += capacity;
  impl_->pending = true;
}

double MaxFlowGraph::Resolve() {
  SILNET_CHECK_MSG(impl_->solved, "MaxFlowGraph::Resolve before Solve");
  if (impl_->pending) impl_->flow = impl_->graph.maxflow(/*reuse_trees=*/true);
  impl_->pending = false;
  return impl_->flow;
}

bool MaxFlowGraph::IsSourceSide(int node) const {
  SILNET_CHECK(impl_->solved && node >= 0 && node < impl_->nodes);
  SILNET_CHECK_MSG(!impl_->pending, "MaxFlowGraph::IsSourceSide with forced nodes: Resolve first");
  return impl_->graph.what_segment(node, BkGraph::SOURCE) == BkGraph::SOURCE;
}

int MaxFlowGraph::num_nodes() const {
  return impl_->nodes;
}

int64_t MaxFlowGraph::num_edges() const {
  return impl_->edges;
}

bool MaxFlowGraph::solved() const {
  return impl_->solved;
}

double MaxFlowGraph::flow() const {
  return impl_->flow;
}

size_t MaxFlowGraph::MemoryBytes() const {
  return static_cast<size_t>(impl_->nodes) * kNodeBytes +
         2 * static_cast<size_t>(impl_->edges) * kArcBytes;
}

}  // namespace silnet::aggregator
