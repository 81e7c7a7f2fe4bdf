#include "aggregator/sync/network_sync.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <utility>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Pair = std::pair<size_t, size_t>;

std::vector<double> RandomOffsets(size_t cameras, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> offset(-40.0, 40.0);
  std::vector<double> truth(cameras);
  for (double& o : truth)
    o = offset(rng);
  return truth;
}

std::vector<Pair> CompleteGraph(size_t cameras) {
  std::vector<Pair> pairs;
  for (size_t i = 0; i < cameras; ++i) {
    for (size_t j = i + 1; j < cameras; ++j)
      pairs.emplace_back(i, j);
  }
  return pairs;
}

// A random spanning tree: each camera, in a random order, joins one camera before it.
std::vector<Pair> RandomTree(size_t cameras, std::mt19937_64& rng) {
  std::vector<size_t> order(cameras);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<Pair> pairs;
  for (size_t k = 1; k < cameras; ++k) {
    const size_t parent = std::uniform_int_distribution<size_t>(0, k - 1)(rng);
    pairs.emplace_back(order[k], order[parent]);
  }
  return pairs;
}

// A random spanning tree plus `extra` further distinct pairs.
std::vector<Pair> SparseGraph(size_t cameras, size_t extra, std::mt19937_64& rng) {
  std::vector<Pair> pairs = RandomTree(cameras, rng);
  std::set<Pair> seen;
  for (const auto& [i, j] : pairs)
    seen.insert({std::min(i, j), std::max(i, j)});
  std::uniform_int_distribution<size_t> camera(0, cameras - 1);
  while (pairs.size() < cameras - 1 + extra) {
    const size_t i = camera(rng), j = camera(rng);
    if (i == j || !seen.insert({std::min(i, j), std::max(i, j)}).second) continue;
    pairs.emplace_back(i, j);
  }
  return pairs;
}

// Cameras 0..n-1 in a band: k joins k+1, k+2 and k+3, so every edge lies in 2-4 triangles.
std::vector<Pair> BandGraph(size_t cameras) {
  std::vector<Pair> pairs;
  for (size_t i = 0; i < cameras; ++i) {
    for (size_t j = i + 1; j < std::min(cameras, i + 4); ++j)
      pairs.emplace_back(i, j);
  }
  return pairs;
}

// Measurements of the true offsets, each with Gaussian noise of its own sigma.
std::vector<OffsetEdge> Measure(const std::vector<Pair>& pairs, const std::vector<double>& truth,
                                std::mt19937_64& rng) {
  std::uniform_real_distribution<double> sigma(0.05, 0.3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<OffsetEdge> edges;
  for (const auto& [i, j] : pairs) {
    const double s = sigma(rng);
    edges.push_back({i, j, truth[i] - truth[j] + s * normal(rng), s});
  }
  return edges;
}

// Adds an error of 3-10 frames, of random sign, to `count` distinct edges; returns them.
std::set<size_t> Corrupt(std::vector<OffsetEdge>& edges, size_t count, std::mt19937_64& rng) {
  std::uniform_int_distribution<size_t> pick(0, edges.size() - 1);
  std::uniform_real_distribution<double> error(3.0, 10.0);
  std::set<size_t> corrupted;
  while (corrupted.size() < count) {
    const size_t e = pick(rng);
    if (!corrupted.insert(e).second) continue;
    edges[e].offset += (rng() % 2 == 0 ? 1.0 : -1.0) * error(rng);
  }
  return corrupted;
}

// Error of camera c's offset relative to the reference, frames.
double Error(const SyncResult& sync, const std::vector<double>& truth, size_t c) {
  return sync.offsets[c] - (truth[c] - truth[sync.reference]);
}

// Checks every camera is synchronised to within `sigmas` of its own sigma.
void ExpectAccurate(const SyncResult& sync, const std::vector<double>& truth, double sigmas) {
  ASSERT_EQ(sync.offsets.size(), truth.size());
  EXPECT_EQ(sync.sigmas[sync.reference], 0.0);
  for (size_t c = 0; c < truth.size(); ++c) {
    EXPECT_TRUE(sync.synchronised[c]) << "camera " << c << ": " << sync.reasons[c];
    EXPECT_TRUE(sync.reasons[c].empty());
    if (c == sync.reference) continue;
    EXPECT_GT(sync.sigmas[c], 0.0);
    EXPECT_LT(std::abs(Error(sync, truth, c)), sigmas * sync.sigmas[c]) << "camera " << c;
  }
}

void ExpectAllUsed(const SyncResult& sync) {
  for (const SyncEdgeResult& e : sync.edges) {
    EXPECT_TRUE(e.used) << e.edge.i << "-" << e.edge.j << ": " << e.rejection;
    EXPECT_TRUE(e.rejection.empty());
  }
}

struct NetworkCase {
  const char* name;
  size_t cameras;
  bool complete;
};

constexpr NetworkCase kNetworks[] = {
    {"complete 8", 8, true},
    {"complete 16", 16, true},
    {"sparse 8", 8, false},
    {"sparse 16", 16, false},
};

std::vector<Pair> Graph(const NetworkCase& network, std::mt19937_64& rng) {
  return network.complete ? CompleteGraph(network.cameras)
                          : SparseGraph(network.cameras, network.cameras, rng);
}

TEST(NetworkSync, RecoversOffsetsOfCompleteAndSparseNetworks) {
  for (const NetworkCase& network : kNetworks) {
    double wls_error = 0.0, raw_error = 0.0;
    size_t count = 0;
    for (uint64_t seed = 0; seed < 30; ++seed) {
      SCOPED_TRACE(testing::Message() << network.name << ", seed " << seed);
      std::mt19937_64 rng(seed);
      const std::vector<double> truth = RandomOffsets(network.cameras, rng);
      const std::vector<OffsetEdge> edges = Measure(Graph(network, rng), truth, rng);
      const SyncResult sync = SynchroniseNetwork(network.cameras, edges);
      EXPECT_EQ(sync.reference, 0u);
      ExpectAccurate(sync, truth, 5.0);
      ExpectAllUsed(sync);
      ASSERT_EQ(sync.edges.size(), edges.size());
      for (size_t e = 0; e < edges.size(); ++e) {
        const OffsetEdge& edge = edges[e];
        const double truth_ij = truth[edge.i] - truth[edge.j];
        wls_error += std::abs(sync.offsets[edge.i] - sync.offsets[edge.j] - truth_ij);
        raw_error += std::abs(edge.offset - truth_ij);
        EXPECT_NEAR(sync.edges[e].residual,
                    edge.offset - (sync.offsets[edge.i] - sync.offsets[edge.j]), 1e-12);
        ++count;
      }
    }
    SCOPED_TRACE(network.name);
    wls_error /= static_cast<double>(count);
    raw_error /= static_cast<double>(count);
    EXPECT_LT(wls_error, (network.complete ? 0.6 : 0.95) * raw_error);
  }
}

TEST(NetworkSync, SigmasMatchTheSpreadOfErrors) {
  double sum = 0.0, sum_squares = 0.0, chi_square = 0.0;
  size_t count = 0, degrees_of_freedom = 0;
  for (const NetworkCase& network : kNetworks) {
    for (uint64_t seed = 100; seed < 160; ++seed) {
      std::mt19937_64 rng(seed);
      const std::vector<double> truth = RandomOffsets(network.cameras, rng);
      const std::vector<OffsetEdge> edges = Measure(Graph(network, rng), truth, rng);
      const SyncResult sync = SynchroniseNetwork(network.cameras, edges);
      for (size_t c = 1; c < network.cameras; ++c) {
        const double z = Error(sync, truth, c) / sync.sigmas[c];
        sum += z;
        sum_squares += z * z;
        ++count;
      }
      // The weighted squared residuals follow chi-square with edges - (cameras - 1) degrees.
      chi_square += static_cast<double>(edges.size()) * std::pow(sync.rms_normalised, 2);
      degrees_of_freedom += edges.size() - (network.cameras - 1);
    }
  }
  const double mean = sum / static_cast<double>(count);
  const double spread = std::sqrt(sum_squares / static_cast<double>(count) - mean * mean);
  EXPECT_LT(std::abs(mean), 0.1);
  EXPECT_GT(spread, 0.9);
  EXPECT_LT(spread, 1.1);
  EXPECT_NEAR(chi_square / static_cast<double>(degrees_of_freedom), 1.0, 0.1);
}

TEST(NetworkSync, RejectsGrossOutliersInCompleteNetworks) {
  for (size_t cameras : {8u, 16u}) {
    for (uint64_t seed = 0; seed < 20; ++seed) {
      SCOPED_TRACE(testing::Message() << cameras << " cameras, seed " << seed);
      std::mt19937_64 rng(seed);
      const std::vector<double> truth = RandomOffsets(cameras, rng);
      std::vector<OffsetEdge> edges = Measure(CompleteGraph(cameras), truth, rng);
      const std::set<size_t> outliers = Corrupt(edges, 3, rng);
      const SyncResult sync = SynchroniseNetwork(cameras, edges);
      ExpectAccurate(sync, truth, 5.0);
      for (size_t e = 0; e < edges.size(); ++e) {
        const SyncEdgeResult& result = sync.edges[e];
        if (outliers.count(e) > 0) {
          EXPECT_FALSE(result.used);
          EXPECT_EQ(result.rejection.rfind("cycle test: ", 0), 0u) << result.rejection;
          EXPECT_GT(result.cycles_failed * 2, result.cycles);
          EXPECT_GT(std::abs(result.residual), 2.0);
        } else {
          EXPECT_TRUE(result.used) << e << ": " << result.rejection;
          EXPECT_LT(result.cycles_failed * 4, result.cycles);  // a 4-sigma noise failure at most
          EXPECT_GE(result.cycles + 3, cameras - 2);  // less those through removed outliers
        }
      }
      EXPECT_LT(sync.rms_normalised, 2.0);
    }
  }
}

TEST(NetworkSync, RejectsOutliersInAHundredCameraNetwork) {
  constexpr size_t kCameras = 100;
  std::mt19937_64 rng(1);
  const std::vector<double> truth = RandomOffsets(kCameras, rng);
  std::vector<OffsetEdge> edges = Measure(CompleteGraph(kCameras), truth, rng);
  const std::set<size_t> outliers = Corrupt(edges, edges.size() / 20, rng);
  const SyncResult sync = SynchroniseNetwork(kCameras, edges);
  ExpectAccurate(sync, truth, 5.0);
  for (size_t e = 0; e < edges.size(); ++e) {
    EXPECT_EQ(sync.edges[e].used, outliers.count(e) == 0) << e << ": " << sync.edges[e].rejection;
  }
}

TEST(NetworkSync, RejectsAnOutlierInABandNetwork) {
  constexpr size_t kCameras = 12;
  for (uint64_t seed = 0; seed < 30; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    std::mt19937_64 rng(seed);
    const std::vector<double> truth = RandomOffsets(kCameras, rng);
    std::vector<OffsetEdge> edges = Measure(BandGraph(kCameras), truth, rng);
    const size_t outlier = *Corrupt(edges, 1, rng).begin();
    const SyncResult sync = SynchroniseNetwork(kCameras, edges);
    ExpectAccurate(sync, truth, 5.0);
    for (size_t e = 0; e < edges.size(); ++e) {
      EXPECT_EQ(sync.edges[e].used, e != outlier) << e << ": " << sync.edges[e].rejection;
    }
  }
}

// Variance of o_c - o_0 along the unique tree path: the sum of the edge variances.
std::vector<double> TreeVariances(size_t cameras, const std::vector<OffsetEdge>& edges) {
  std::vector<double> variance(cameras, -1.0);
  variance[0] = 0.0;
  for (size_t round = 0; round < cameras; ++round) {
    for (const OffsetEdge& e : edges) {
      if (variance[e.i] >= 0.0 && variance[e.j] < 0.0)
        variance[e.j] = variance[e.i] + e.sigma * e.sigma;
      if (variance[e.j] >= 0.0 && variance[e.i] < 0.0)
        variance[e.i] = variance[e.j] + e.sigma * e.sigma;
    }
  }
  return variance;
}

TEST(NetworkSync, TreeFitsEveryEdgeExactly) {
  constexpr size_t kCameras = 10;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    std::mt19937_64 rng(seed);
    const std::vector<double> truth = RandomOffsets(kCameras, rng);
    std::vector<OffsetEdge> edges = Measure(RandomTree(kCameras, rng), truth, rng);
    Corrupt(edges, 1, rng);  // undetectable without cycles: the tree is still fitted exactly
    const SyncResult sync = SynchroniseNetwork(kCameras, edges);
    ExpectAllUsed(sync);
    const std::vector<double> variance = TreeVariances(kCameras, edges);
    for (size_t c = 0; c < kCameras; ++c) {
      EXPECT_TRUE(sync.synchronised[c]);
      EXPECT_NEAR(sync.sigmas[c], std::sqrt(variance[c]), 1e-9);
    }
    for (const SyncEdgeResult& e : sync.edges) {
      EXPECT_EQ(e.cycles, 0u);
      EXPECT_NEAR(e.residual, 0.0, 1e-9);
    }
    EXPECT_NEAR(sync.rms_residual, 0.0, 1e-9);
  }
}

// Thesis figure 3.8: the MIT sequence's six pairwise offsets t_ij = x_j - x_i with their
// sigmas, and the offsets after network synchronisation, t_01, t_02, t_03 = -8.50, -8.98, -7.89.
TEST(NetworkSync, MatchesTheThesisMitExample) {
  const std::vector<OffsetEdge> edges = {
      {0, 1, 8.7, 0.80},  {0, 2, 8.1, 1.96},   {0, 3, 7.7, 1.57},
      {1, 2, 0.93, 1.65}, {1, 3, -0.54, 0.72}, {2, 3, -1.20, 1.27},
  };
  const SyncResult sync = SynchroniseNetwork(4, edges);
  ExpectAllUsed(sync);
  EXPECT_EQ(sync.reference, 0u);
  EXPECT_NEAR(sync.offsets[1], -8.50, 0.005);
  EXPECT_NEAR(sync.offsets[2], -8.98, 0.005);
  EXPECT_NEAR(sync.offsets[3], -7.89, 0.005);
  for (const SyncEdgeResult& e : sync.edges) {
    EXPECT_EQ(e.cycles, 2u);
    EXPECT_EQ(e.cycles_failed, 0u);
  }
}

TEST(NetworkSync, CountsTheCyclesOfAnOutlier) {
  std::mt19937_64 rng(7);
  const std::vector<double> truth = RandomOffsets(4, rng);
  std::vector<OffsetEdge> edges = Measure(CompleteGraph(4), truth, rng);
  edges[2].offset += 5.0;
  const SyncResult sync = SynchroniseNetwork(4, edges);
  ExpectAccurate(sync, truth, 5.0);
  for (size_t e = 0; e < edges.size(); ++e) {
    EXPECT_EQ(sync.edges[e].used, e != 2);
    // Edge 3 (1-2) keeps both its triangles; the others lose the one through the outlier.
    EXPECT_EQ(sync.edges[e].cycles, e == 2 || e == 3 ? 2u : 1u);
    EXPECT_EQ(sync.edges[e].cycles_failed, e == 2 ? 2u : 0u);
  }
  EXPECT_EQ(sync.edges[2].rejection, "cycle test: 2 of 2 triangles fail to close");
  EXPECT_NEAR(sync.edges[2].residual, 5.0, 1.0);
}

TEST(NetworkSync, FlagsCamerasOutsideTheReferenceComponent) {
  std::mt19937_64 rng(3);
  const std::vector<double> truth = RandomOffsets(7, rng);
  // Cameras 0-3 complete, 4-5 linked to each other only, 6 without measurements.
  std::vector<Pair> pairs = CompleteGraph(4);
  pairs.emplace_back(4, 5);
  const std::vector<OffsetEdge> edges = Measure(pairs, truth, rng);
  const SyncResult sync = SynchroniseNetwork(7, edges);
  EXPECT_EQ(sync.reference, 0u);
  for (size_t c = 0; c < 7; ++c) {
    EXPECT_EQ(sync.synchronised[c], c < 4);
    EXPECT_EQ(sync.reasons[c].empty(), c < 4);
  }
  EXPECT_EQ(sync.reasons[4],
            "no offset measurement links camera 4 to the reference's component (camera 0)");
  EXPECT_EQ(sync.reasons[6], "camera 6 has no offset measurements");
  EXPECT_EQ(sync.offsets[5], 0.0);
  EXPECT_FALSE(sync.edges.back().used);
  EXPECT_EQ(sync.edges.back().rejection, "not connected to the reference's component (camera 0)");
  for (size_t e = 0; e + 1 < edges.size(); ++e)
    EXPECT_TRUE(sync.edges[e].used);
}

TEST(NetworkSync, ReferenceIsTheLowestCameraOfTheLargestComponent) {
  std::mt19937_64 rng(5);
  const std::vector<double> truth = RandomOffsets(6, rng);
  std::vector<Pair> pairs = {{1, 0}};
  for (const auto& [i, j] : CompleteGraph(4))
    pairs.emplace_back(i + 2, j + 2);
  const SyncResult sync = SynchroniseNetwork(6, Measure(pairs, truth, rng));
  EXPECT_EQ(sync.reference, 2u);
  EXPECT_EQ(sync.offsets[2], 0.0);
  EXPECT_FALSE(sync.synchronised[0]);
  EXPECT_FALSE(sync.synchronised[1]);
  EXPECT_NEAR(Error(sync, truth, 5), 0.0, 5.0 * sync.sigmas[5]);
}

TEST(NetworkSync, RejectsAllLinksOfACameraWhoseLinksAreOutliers) {
  constexpr size_t kCameras = 8;  // cameras 0-6 complete; camera 7 has only wrong links
  for (size_t links : {2u, 3u}) {
    for (uint64_t seed = 0; seed < 10; ++seed) {
      SCOPED_TRACE(testing::Message() << links << " links, seed " << seed);
      std::mt19937_64 rng(seed);
      const std::vector<double> truth = RandomOffsets(kCameras, rng);
      std::vector<Pair> pairs = CompleteGraph(kCameras - 1);
      for (size_t k = 0; k < links; ++k)
        pairs.emplace_back(7, 2 * k);
      std::vector<OffsetEdge> edges = Measure(pairs, truth, rng);
      const double errors[] = {6.0, -4.0, 9.0};
      for (size_t k = 0; k < links; ++k)
        edges[edges.size() - links + k].offset += errors[k];
      const SyncResult sync = SynchroniseNetwork(kCameras, edges);
      EXPECT_FALSE(sync.synchronised[7]);
      EXPECT_EQ(sync.reasons[7],
                "all " + std::to_string(links) + " links of camera 7 were rejected as outliers");
      for (size_t e = 0; e < edges.size(); ++e) {
        const bool to_7 = edges[e].i == 7;
        EXPECT_EQ(sync.edges[e].used, !to_7) << sync.edges[e].rejection;
        if (to_7) {
          EXPECT_EQ(sync.edges[e].rejection.rfind("cycle test: ", 0), 0u);
        }
      }
      for (size_t c = 1; c + 1 < kCameras; ++c)
        EXPECT_LT(std::abs(Error(sync, truth, c)), 5.0 * sync.sigmas[c]);
    }
  }
}

TEST(NetworkSync, ClearsEdgesWhoseFailuresAnOutlierExplains) {
  // Camera 5 is linked to cameras 0 and 1 only; its one triangle fails because edge 0-1 is
  // wrong, which fails all its triangles and goes; camera 5's links are then cleared.
  std::mt19937_64 rng(2);
  const std::vector<double> truth = RandomOffsets(6, rng);
  std::vector<Pair> pairs = CompleteGraph(5);
  pairs.emplace_back(5, 0);
  pairs.emplace_back(5, 1);
  std::vector<OffsetEdge> edges = Measure(pairs, truth, rng);
  edges[0].offset += 5.0;
  const SyncResult sync = SynchroniseNetwork(6, edges);
  ExpectAccurate(sync, truth, 5.0);
  EXPECT_EQ(sync.edges[0].rejection, "cycle test: 4 of 4 triangles fail to close");
  for (size_t e = 1; e < edges.size(); ++e)
    EXPECT_TRUE(sync.edges[e].used) << e << ": " << sync.edges[e].rejection;
  EXPECT_EQ(sync.edges.back().cycles_failed, 1u);  // as last counted, with edge 0-1
}

TEST(NetworkSync, AnInconsistentTriangleAloneCannotBeResolved) {
  // Edge 1-2, the least certain, takes the largest share of the misclosure and goes first;
  // the other two are as suspect and nothing is left to clear them.
  const SyncResult sync =
      SynchroniseNetwork(3, {{0, 1, 1.0, 0.1}, {1, 2, 2.0, 0.3}, {2, 0, 2.0, 0.1}});
  for (const SyncEdgeResult& e : sync.edges)
    EXPECT_FALSE(e.used);
  EXPECT_EQ(sync.edges[1].rejection, "cycle test: 1 of 1 triangles fail to close");
  for (size_t e : {0u, 2u}) {
    EXPECT_EQ(sync.edges[e].rejection,
              "cycle test: 1 of 1 triangles fail to close, as for the rejected edge 1-2, and no "
              "triangle is left to tell which is wrong");
  }
  EXPECT_EQ(sync.reference, 0u);
  EXPECT_EQ(sync.reasons[1], "all 2 links of camera 1 were rejected as outliers");
  EXPECT_FALSE(sync.synchronised[2]);
}

TEST(NetworkSync, NamesRejectedLinksBetweenComponents) {
  // Cameras 5-7 form a consistent triangle whose two links to camera 0 disagree.
  std::mt19937_64 rng(4);
  const std::vector<double> truth = RandomOffsets(8, rng);
  std::vector<Pair> pairs = CompleteGraph(5);
  for (const Pair& p : std::vector<Pair>{{5, 6}, {6, 7}, {7, 5}, {5, 0}, {6, 0}})
    pairs.push_back(p);
  std::vector<OffsetEdge> edges = Measure(pairs, truth, rng);
  edges[edges.size() - 2].offset += 6.0;
  edges[edges.size() - 1].offset -= 4.0;
  const SyncResult sync = SynchroniseNetwork(8, edges);
  EXPECT_EQ(sync.reference, 0u);
  EXPECT_FALSE(sync.edges[edges.size() - 2].used);
  EXPECT_FALSE(sync.edges[edges.size() - 1].used);
  for (size_t c = 5; c < 8; ++c) {
    EXPECT_FALSE(sync.synchronised[c]);
    EXPECT_EQ(sync.reasons[c], "the links between camera " + std::to_string(c) +
                                   "'s component and the reference's component (camera 0) were "
                                   "rejected as outliers");
  }
  EXPECT_EQ(sync.edges[10].rejection, "not connected to the reference's component (camera 0)");
}

TEST(NetworkSync, ParallelEdgesAreSeparateMeasurements) {
  // Two measurements of one pair are averaged with weights 1/sigma^2.
  SyncResult sync = SynchroniseNetwork(2, {{0, 1, 2.0, 0.1}, {0, 1, 2.1, 0.2}});
  ExpectAllUsed(sync);
  EXPECT_NEAR(sync.offsets[1], -(2.0 * 100.0 + 2.1 * 25.0) / 125.0, 1e-12);
  EXPECT_NEAR(sync.sigmas[1], 1.0 / std::sqrt(125.0), 1e-12);
  EXPECT_NEAR(sync.edges[1].residual, 2.1 - 2.02, 1e-12);

  // Disagreeing beyond their sigmas: the residual check drops the worse one; the other is
  // then the only link and stays.
  sync = SynchroniseNetwork(2, {{0, 1, 2.0, 0.1}, {1, 0, -8.0, 0.2}});
  EXPECT_TRUE(sync.edges[0].used);
  EXPECT_FALSE(sync.edges[1].used);
  EXPECT_EQ(sync.edges[1].rejection.rfind("residual check: ", 0), 0u) << sync.edges[1].rejection;
  EXPECT_NEAR(sync.offsets[1], -2.0, 1e-12);
  EXPECT_NEAR(sync.edges[1].residual, -6.0, 1e-12);
  EXPECT_NEAR(sync.rms_residual, 0.0, 1e-12);

  // A wrong parallel edge in a complete network fails its triangles.
  std::mt19937_64 rng(11);
  const std::vector<double> truth = RandomOffsets(5, rng);
  std::vector<Pair> pairs = CompleteGraph(5);
  pairs.emplace_back(1, 0);
  std::vector<OffsetEdge> edges = Measure(pairs, truth, rng);
  edges.back().offset += 4.0;
  sync = SynchroniseNetwork(5, edges);
  ExpectAccurate(sync, truth, 5.0);
  EXPECT_EQ(sync.edges.back().rejection, "cycle test: 3 of 3 triangles fail to close");
  EXPECT_EQ(sync.edges[0].cycles, 3u);
  for (size_t e = 0; e + 1 < edges.size(); ++e)
    EXPECT_TRUE(sync.edges[e].used) << sync.edges[e].rejection;
}

TEST(NetworkSync, HandlesEmptyNetworks) {
  const SyncResult none = SynchroniseNetwork(0, {});
  EXPECT_TRUE(none.offsets.empty());
  EXPECT_TRUE(none.edges.empty());
  const SyncResult one = SynchroniseNetwork(1, {});
  ASSERT_EQ(one.synchronised.size(), 1u);
  EXPECT_TRUE(one.synchronised[0]);
  EXPECT_EQ(one.offsets[0], 0.0);
  EXPECT_EQ(one.sigmas[0], 0.0);
}

TEST(NetworkSync, ThrowsOnInvalidInput) {
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 2, 1.0, 0.1}}), CheckError);
  EXPECT_THROW(SynchroniseNetwork(2, {{1, 1, 1.0, 0.1}}), CheckError);
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 1, 1.0, 0.0}}), CheckError);
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 1, 1.0, -0.1}}), CheckError);
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 1, NAN, 0.1}}), CheckError);
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 1, 1.0, INFINITY}}), CheckError);
  SyncOptions options;
  options.outlier_fraction = 1.5;
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 1, 1.0, 0.1}}, options), CheckError);
  options = {};
  options.cycle_sigmas = 0.0;
  EXPECT_THROW(SynchroniseNetwork(2, {{0, 1, 1.0, 0.1}}, options), CheckError);
}

}  // namespace
}  // namespace silnet::aggregator
