// The max-flow layer against a hand-computed graph and against brute-force minimum cuts of
// random small graphs (all 2^n labellings); incremental re-solves after forcing nodes to the
// source against the same brute force and against grid graphs built forced from scratch.

#include "aggregator/stereo/max_flow.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Source -> a 4, source -> b 2, a -> b 1, a -> sink 2, b -> sink 4. Flow: 2 along s-a-t, 2
// along s-b-t, 1 along s-a-b-t = 5. Cuts: {s} 6, {s, a} 2 + 1 + 2 = 5, {s, b} 4 + 4 = 8,
// {s, a, b} 2 + 4 = 6, so the minimum cut {s, a} is unique.
TEST(MaxFlowGraph, HandComputedGraph) {
  MaxFlowGraph graph(2, 1);
  const int a = graph.AddNodes(2);
  const int b = a + 1;
  graph.AddTerminalCapacities(a, 4, 2);
  graph.AddTerminalCapacities(b, 2, 4);
  graph.AddEdge(a, b, 1, 0);
  EXPECT_FALSE(graph.solved());
  EXPECT_DOUBLE_EQ(graph.Solve(), 5.0);
  EXPECT_DOUBLE_EQ(graph.flow(), 5.0);
  EXPECT_TRUE(graph.IsSourceSide(a));
  EXPECT_FALSE(graph.IsSourceSide(b));
  EXPECT_EQ(graph.num_nodes(), 2);
  EXPECT_EQ(graph.num_edges(), 1);
  EXPECT_EQ(graph.MemoryBytes(), 2u * 48u + 2u * 32u);
}

// The graph above with b forced to the source: cuts {s, b} 4 + 4 = 8 and {s, a, b} 2 + 4 = 6.
TEST(MaxFlowGraph, ResolveAfterForcingHandComputedGraph) {
  MaxFlowGraph graph(2, 1);
  const int a = graph.AddNodes(2);
  const int b = a + 1;
  graph.AddTerminalCapacities(a, 4, 2);
  graph.AddTerminalCapacities(b, 2, 4);
  graph.AddEdge(a, b, 1, 0);
  EXPECT_DOUBLE_EQ(graph.Solve(), 5.0);
  graph.ForceSourceSide(b);
  EXPECT_THROW(graph.IsSourceSide(a), CheckError);  // labels stale until Resolve
  EXPECT_DOUBLE_EQ(graph.Resolve(), 6.0);
  EXPECT_DOUBLE_EQ(graph.flow(), 6.0);
  EXPECT_TRUE(graph.IsSourceSide(a));
  EXPECT_TRUE(graph.IsSourceSide(b));
  EXPECT_DOUBLE_EQ(graph.Resolve(), 6.0);  // nothing forced since: unchanged
}

struct RandomGraph {
  int n = 0;
  std::vector<double> source, sink;  // t-link capacities per node
  struct Edge {
    int a, b;
    double ab, ba;
  };
  std::vector<Edge> edges;
};

RandomGraph MakeRandomGraph(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> capacity(0.0, 10.0);
  std::bernoulli_distribution present(0.4), zero(0.2);
  RandomGraph g;
  g.n = n;
  for (int i = 0; i < n; ++i) {
    g.source.push_back(zero(rng) ? 0.0 : capacity(rng));
    g.sink.push_back(zero(rng) ? 0.0 : capacity(rng));
  }
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      if (present(rng)) g.edges.push_back({a, b, capacity(rng), zero(rng) ? 0.0 : capacity(rng)});
    }
  }
  return g;
}

// Capacity of the cut whose source side is the set bits of `mask`.
double CutCapacity(const RandomGraph& g, unsigned mask) {
  const auto on_source = [mask](int i) { return ((mask >> i) & 1u) != 0; };
  double cut = 0;
  for (int i = 0; i < g.n; ++i)
    cut += on_source(i) ? g.sink[i] : g.source[i];
  for (const auto& e : g.edges) {
    if (on_source(e.a) && !on_source(e.b)) cut += e.ab;
    if (on_source(e.b) && !on_source(e.a)) cut += e.ba;
  }
  return cut;
}

TEST(MaxFlowGraph, MatchesBruteForceMinimumCut) {
  constexpr int kNodes = 10;
  for (int seed = 0; seed < 50; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    const RandomGraph g = MakeRandomGraph(rng, kNodes);
    double best = std::numeric_limits<double>::infinity();
    for (unsigned mask = 0; mask < (1u << kNodes); ++mask)
      best = std::min(best, CutCapacity(g, mask));

    MaxFlowGraph graph(kNodes, static_cast<int64_t>(g.edges.size()));
    ASSERT_EQ(graph.AddNodes(kNodes), 0);
    for (int i = 0; i < kNodes; ++i)
      graph.AddTerminalCapacities(i, g.source[i], g.sink[i]);
    for (const auto& e : g.edges)
      graph.AddEdge(e.a, e.b, e.ab, e.ba);
    const double flow = graph.Solve();
    unsigned labels = 0;
    for (int i = 0; i < kNodes; ++i)
      labels |= graph.IsSourceSide(i) ? (1u << i) : 0u;
    EXPECT_NEAR(flow, best, 1e-9 * (1 + best)) << "seed " << seed;
    EXPECT_NEAR(CutCapacity(g, labels), best, 1e-9 * (1 + best)) << "seed " << seed;
  }
}

// Minimum cut capacity over the labellings with the bits of `forced` on the source side and
// those of `forced_out` on the sink side.
double ForcedMinimumCut(const RandomGraph& g, unsigned forced, unsigned forced_out = 0) {
  double best = std::numeric_limits<double>::infinity();
  for (unsigned mask = 0; mask < (1u << g.n); ++mask) {
    if ((mask & forced) == forced && (mask & forced_out) == 0)
      best = std::min(best, CutCapacity(g, mask));
  }
  return best;
}

// The max-flow graph of `g`, solved.
MaxFlowGraph SolvedGraph(const RandomGraph& g) {
  MaxFlowGraph graph(g.n, static_cast<int64_t>(g.edges.size()));
  graph.AddNodes(g.n);
  for (int i = 0; i < g.n; ++i)
    graph.AddTerminalCapacities(i, g.source[i], g.sink[i]);
  for (const auto& e : g.edges)
    graph.AddEdge(e.a, e.b, e.ab, e.ba);
  graph.Solve();
  return graph;
}

// Resolves `graph` (of `g`) and checks its flow and labels against the brute-force minimum cut
// with the nodes of `in` on the source side and those of `out` on the sink side.
void ExpectForcedCut(MaxFlowGraph* graph, const RandomGraph& g, unsigned in, unsigned out) {
  const double flow = graph->Resolve();
  const double best = ForcedMinimumCut(g, in, out);
  unsigned labels = 0;
  for (int i = 0; i < g.n; ++i)
    labels |= graph->IsSourceSide(i) ? (1u << i) : 0u;
  EXPECT_EQ(labels & in, in);
  EXPECT_EQ(labels & out, 0u);
  EXPECT_NEAR(flow, best, 1e-9 * (1 + best));
  EXPECT_NEAR(CutCapacity(g, labels), best, 1e-9 * (1 + best));
}

TEST(MaxFlowGraph, ResolveMatchesBruteForceForcedCut) {
  constexpr int kNodes = 10;
  for (int seed = 0; seed < 50; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed) + 100);
    const RandomGraph g = MakeRandomGraph(rng, kNodes);
    MaxFlowGraph graph = SolvedGraph(g);
    // Three rounds, each forcing one or two more nodes (possibly again).
    std::uniform_int_distribution<int> node(0, kNodes - 1);
    unsigned forced = 0;
    for (int round = 0; round < 3; ++round) {
      for (int k = 0; k <= round % 2; ++k) {
        const int i = node(rng);
        graph.ForceSourceSide(i);
        forced |= 1u << i;
      }
      SCOPED_TRACE("seed " + std::to_string(seed) + " round " + std::to_string(round));
      ExpectForcedCut(&graph, g, forced, 0);
    }
  }
}

TEST(MaxFlowGraph, ResolveMatchesBruteForceCutWithNodesForcedToEitherSide) {
  constexpr int kNodes = 10;
  for (int seed = 0; seed < 50; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed) + 200);
    const RandomGraph g = MakeRandomGraph(rng, kNodes);
    MaxFlowGraph graph = SolvedGraph(g);
    // Four rounds alternating sinks and sources, each node forced at most to one side.
    std::uniform_int_distribution<int> node(0, kNodes - 1);
    unsigned in = 0, out = 0;
    for (int round = 0; round < 4; ++round) {
      for (int k = 0; k < 2; ++k) {
        const int i = node(rng);
        if (((in | out) >> i) & 1u) continue;
        if (round % 2 == 0) {
          graph.ForceSinkSide(i);
          out |= 1u << i;
        } else {
          graph.ForceSourceSide(i);
          in |= 1u << i;
        }
      }
      SCOPED_TRACE("seed " + std::to_string(seed) + " round " + std::to_string(round));
      ExpectForcedCut(&graph, g, in, out);
    }
  }
}

// A 3D grid graph with 6-neighbour n-links and integer capacities (exact in doubles, so the
// flows and the labels, the minimum cut with the largest source side, must match exactly).
struct GridGraph {
  int side = 0;
  std::vector<double> source, sink;
  std::vector<RandomGraph::Edge> edges;
};

GridGraph MakeGridGraph(std::mt19937_64& rng, int side) {
  std::uniform_int_distribution<int> link(0, 9), terminal(0, 6);
  GridGraph g;
  g.side = side;
  const int n = side * side * side;
  const auto id = [side](int i, int j, int k) { return (k * side + j) * side + i; };
  for (int c = 0; c < n; ++c) {
    g.source.push_back(terminal(rng));
    g.sink.push_back(terminal(rng));
  }
  for (int k = 0; k < side; ++k)
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        const double w = link(rng);
        if (i + 1 < side) g.edges.push_back({id(i, j, k), id(i + 1, j, k), w, w});
        if (j + 1 < side) g.edges.push_back({id(i, j, k), id(i, j + 1, k), w, w});
        if (k + 1 < side) g.edges.push_back({id(i, j, k), id(i, j, k + 1), w, w});
      }
  return g;
}

// The graph of `g`, unsolved; nodes of `forced` get `force` more source capacity.
MaxFlowGraph BuildGrid(const GridGraph& g, const std::vector<int>& forced, double force) {
  const int n = static_cast<int>(g.source.size());
  MaxFlowGraph graph(n, static_cast<int64_t>(g.edges.size()));
  graph.AddNodes(n);
  for (int i = 0; i < n; ++i)
    graph.AddTerminalCapacities(i, g.source[i], g.sink[i]);
  for (int i : forced)
    graph.AddTerminalCapacities(i, force, 0);
  for (const auto& e : g.edges)
    graph.AddEdge(e.a, e.b, e.ab, e.ba);
  return graph;
}

TEST(MaxFlowGraph, ResolveMatchesGridGraphsSolvedFromScratch) {
  constexpr int kSide = 14;
  for (int seed = 0; seed < 6; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    const GridGraph g = MakeGridGraph(rng, kSide);
    double sink_total = 0;
    for (double c : g.sink)
      sink_total += c;
    const int n = static_cast<int>(g.source.size());
    MaxFlowGraph incremental = BuildGrid(g, {}, 0);
    incremental.Solve();
    // Rounds forcing six sink-side nodes from a random start and three random nodes.
    std::uniform_int_distribution<int> node(0, n - 1);
    std::vector<int> forced;
    for (int round = 0; round < 4; ++round) {
      std::vector<int> fresh;
      for (int i = node(rng); i < n && fresh.size() < 6; ++i) {
        if (!incremental.IsSourceSide(i)) fresh.push_back(i);
      }
      for (int k = 0; k < 3; ++k)
        fresh.push_back(node(rng));
      for (int i : fresh)
        incremental.ForceSourceSide(i);
      forced.insert(forced.end(), fresh.begin(), fresh.end());
      const double flow = incremental.Resolve();
      MaxFlowGraph scratch = BuildGrid(g, forced, sink_total + 1);
      ASSERT_EQ(flow, scratch.Solve()) << "seed " << seed << " round " << round;
      int differ = 0;
      for (int i = 0; i < n; ++i)
        differ += incremental.IsSourceSide(i) != scratch.IsSourceSide(i) ? 1 : 0;
      EXPECT_EQ(differ, 0) << "seed " << seed << " round " << round;
      for (int i : forced)
        EXPECT_TRUE(incremental.IsSourceSide(i));
    }
  }
}

// Source capacity added after the solve (the adaptive cut's raised ballooning) gives the cut of
// the graph built with it, twice in a row, and the forcing afterwards still holds.
TEST(MaxFlowGraph, AddedSourceCapacityMatchesGridGraphsSolvedFromScratch) {
  constexpr int kSide = 14;
  for (int seed = 0; seed < 6; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(100 + seed));
    GridGraph g = MakeGridGraph(rng, kSide);
    const int n = static_cast<int>(g.source.size());
    MaxFlowGraph incremental = BuildGrid(g, {}, 0);
    const double first = incremental.Solve();
    for (int raise = 0; raise < 2; ++raise) {
      for (int i = 0; i < n; ++i) {
        incremental.AddSourceCapacity(i, g.source[i]);  // doubles it: exact in doubles
        g.source[i] *= 2;
      }
      const double flow = incremental.Resolve();
      MaxFlowGraph scratch = BuildGrid(g, {}, 0);
      ASSERT_EQ(flow, scratch.Solve()) << "seed " << seed << " raise " << raise;
      EXPECT_GE(flow, first);
      int differ = 0;
      for (int i = 0; i < n; ++i)
        differ += incremental.IsSourceSide(i) != scratch.IsSourceSide(i) ? 1 : 0;
      EXPECT_EQ(differ, 0) << "seed " << seed << " raise " << raise;
    }
    const int node = n / 2;
    const bool source_side = incremental.IsSourceSide(node);
    if (source_side)
      incremental.ForceSinkSide(node);
    else
      incremental.ForceSourceSide(node);
    incremental.Resolve();
    EXPECT_NE(incremental.IsSourceSide(node), source_side);
    EXPECT_THROW(incremental.AddSourceCapacity(0, 1), CheckError);  // after forcing
  }
}

TEST(MaxFlowGraph, EmptyGraphAndMisuse) {
  MaxFlowGraph empty(0, 0);
  EXPECT_EQ(empty.Solve(), 0.0);
  EXPECT_THROW(empty.Solve(), CheckError);

  MaxFlowGraph graph(0, 0);
  EXPECT_THROW(graph.AddNodes(0), CheckError);
  graph.AddNodes(3);
  EXPECT_THROW(graph.AddEdge(0, 0, 1, 1), CheckError);
  EXPECT_THROW(graph.AddEdge(0, 3, 1, 1), CheckError);
  EXPECT_THROW(graph.AddEdge(0, 1, -1, 1), CheckError);
  EXPECT_THROW(graph.AddTerminalCapacities(0, -1, 0), CheckError);
  EXPECT_THROW(graph.IsSourceSide(0), CheckError);  // before Solve
  graph.AddTerminalCapacities(0, 1, 0);
  graph.AddEdge(0, 1, 2, 0);
  graph.AddTerminalCapacities(1, 0, 3);
  EXPECT_THROW(graph.ForceSourceSide(0), CheckError);  // before Solve
  EXPECT_THROW(graph.AddSourceCapacity(0, 1), CheckError);
  EXPECT_THROW(graph.Resolve(), CheckError);
  EXPECT_DOUBLE_EQ(graph.Solve(), 1.0);
  EXPECT_THROW(graph.AddNodes(1), CheckError);
  EXPECT_THROW(graph.AddEdge(0, 1, 1, 1), CheckError);
  EXPECT_THROW(graph.AddTerminalCapacities(0, 1, 0), CheckError);
  EXPECT_THROW(graph.ForceSourceSide(3), CheckError);
  EXPECT_THROW(graph.AddSourceCapacity(0, -1), CheckError);
  EXPECT_TRUE(graph.IsSourceSide(2));  // isolated: either side, reported as source
}

TEST(MaxFlowGraph, MovesKeepTheGraph) {
  MaxFlowGraph a(0, 0);
  a.AddNodes(1);
  a.AddTerminalCapacities(0, 2, 3);
  MaxFlowGraph b = std::move(a);
  EXPECT_DOUBLE_EQ(b.Solve(), 2.0);
  EXPECT_FALSE(b.IsSourceSide(0));
}

}  // namespace
}  // namespace silnet::aggregator
