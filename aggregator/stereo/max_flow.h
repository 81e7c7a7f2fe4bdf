#pragma once
// Minimum s-t cut by maximum flow (thesis B-3): the Boykov-Kolmogorov augmenting-path
// algorithm (PAMI 2004, "An Experimental Comparison of Min-Cut/Max-Flow Algorithms for Energy
// Minimization in Vision"), fast on the sparse, uniformly connected grid graphs of volumetric
// stereo. A thin layer over Debian's libmaxflow (version 3.0.x) so that no other file includes
// its header; capacities are doubles.

#include <cstddef>
#include <cstdint>
#include <memory>

namespace silnet::aggregator {

// A flow graph with a source, a sink and non-negative capacities on terminal links
// (t-links) and on directed pairs of neighbour links (n-links). Build it, call Solve() once,
// then read which side of the minimum cut each node is on. After Solve() nodes may be forced
// to the source or the sink side and the cut updated by Resolve(), which reuses the search trees
// and the flow found so far (Kohli and Torr, "Efficiently Solving Dynamic Markov Random Fields
// Using Graph Cuts", ICCV 2005): far cheaper than solving the changed graph from scratch when few
// nodes change. Node ids are 0, 1, 2, ... in the order added. Not copyable; not thread-safe.
class MaxFlowGraph {
 public:
  // An empty graph; the expected counts only size the first allocation (both may be 0).
  MaxFlowGraph(int64_t expected_nodes, int64_t expected_edges);
  ~MaxFlowGraph();
  MaxFlowGraph(const MaxFlowGraph&) = delete;
  MaxFlowGraph& operator=(const MaxFlowGraph&) = delete;
  MaxFlowGraph(MaxFlowGraph&&) noexcept;
  MaxFlowGraph& operator=(MaxFlowGraph&&) noexcept;

  // Adds `count` > 0 nodes and returns the id of the first. Node ids are ints: the total
  // must stay below 2^31 (CheckError otherwise).
  int AddNodes(int count);
  // Adds capacity from the source to `node` and from `node` to the sink (both >= 0); may
  // be called several times per node, capacities add up. Before Solve() only.
  void AddTerminalCapacities(int node, double source_capacity, double sink_capacity);
  // Adds the n-link pair a -> b (capacity `a_to_b`) and b -> a (`b_to_a`), both >= 0, a != b.
  // Before Solve() only.
  void AddEdge(int a, int b, double a_to_b, double b_to_a);

  // Computes the maximum flow (= the capacity of the minimum cut) and returns it. Call once,
  // after the graph is complete (CheckError on a second call or on changes other than
  // forcing afterwards).
  double Solve();

  // After Solve(): ties `node` to the source (ForceSourceSide) or the sink (ForceSinkSide)
  // with a capacity larger than all the original capacities together, so no minimum cut
  // separates it from that terminal and no minimum cut's capacity includes the tie. Takes
  // effect at the next Resolve(); forcing a node twice to one side is harmless, to both
  // sides is the caller's error (the cut then splits one of the ties).
  void ForceSourceSide(int node);
  void ForceSinkSide(int node);
  // After Solve() and before any node is forced: adds `capacity` (>= 0) to the source t-link
  // of `node`. Takes effect at the next Resolve(), which reuses the flow found so far; the
  // forcing capacity of later ForceSourceSide/ForceSinkSide calls includes it.
  void AddSourceCapacity(int node, double capacity);
  // After Solve(): the maximum flow of the graph with the nodes forced (or capacities added)
  // since the last Solve() or Resolve(), computed from the previous flow and search trees. Returns
  // the new value, the capacity of the changed graph's minimum cut (the forcing capacities are
  // never cut, so it counts only the original links).
  double Resolve();

  // After Solve(), with no forcing pending: true iff `node` is on the source side of
  // the minimum cut. A node that can be on either side of some minimum cut (one that cannot
  // reach the sink in the residual graph) counts as source, so in exact arithmetic the labels
  // are the minimum cut with the largest source side, whatever the order of solves.
  bool IsSourceSide(int node) const;

  int num_nodes() const;      // nodes added
  int64_t num_edges() const;  // AddEdge calls (each is two directed arcs)
  bool solved() const;        // Solve() has run
  double flow() const;        // the value the last Solve() or Resolve() returned (0 before)
  // Bytes the library holds for nodes and arcs at the current counts (its node and arc
  // records on a 64-bit build: 48 and 32 bytes with double capacities), excluding
  // allocation slack and the small search queues.
  size_t MemoryBytes() const;

 private:
  void Force(int node, bool source);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace silnet::aggregator
