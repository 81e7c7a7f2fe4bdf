#pragma once
// Network synchronisation (thesis 3.3): the cameras' time offsets from the pairwise offset
// measurements. The measurements form a graph; an edge whose triangle cycles mostly fail to
// sum to zero is an outlier and is removed (the cycle test); the offsets are then the
// weighted least-squares solution (rows scaled by 1/sigma) with a reference camera fixed at
// zero, and edges it leaves with gross residuals are removed too.
// The graph is undirected (an edge i-j also gives o_j - o_i = -offset); parallel edges
// between two cameras are separate measurements, each in its own triangle cycles.

#include <cstddef>
#include <string>
#include <vector>

namespace silnet::aggregator {

// One pairwise measurement: offset = o_i - o_j (frame k of camera i meets frame k + offset
// of camera j, where o is each camera's time_offset), with its standard deviation in frames.
struct OffsetEdge {
  size_t i = 0;
  size_t j = 0;
  double offset = 0.0;
  double sigma = 0.1;
};

// Settings of the synchronisation.
struct SyncOptions {
  // A triangle cycle fails when |o_ij + o_jk + o_ki| exceeds cycle_sigmas times its combined
  // sigma and at least cycle_min_frames.
  double cycle_sigmas = 4.0;
  double cycle_min_frames = 0.2;
  // An edge is an outlier when more than this fraction of its cycles fail (and at least
  // one does); edges are removed worst first, the cycles re-evaluated after each removal.
  // An outlier whose last cycles go with a removed edge is cleared when that edge failed
  // more cycles, and rejected with it when both failed the same (nothing tells them apart).
  double outlier_fraction = 0.5;
  // After the least-squares solution, an edge whose residual exceeds this many sigmas (and
  // cycle_min_frames) is also removed, the worst in sigmas first, and the system solved
  // again; an edge whose removal would disconnect a camera is kept.
  double residual_sigmas = 5.0;
};

// What became of one measurement.
struct SyncEdgeResult {
  OffsetEdge edge;
  bool used = false;         // part of the final least-squares solution
  std::string rejection;     // why not used; empty when used
  size_t cycles = 0;         // triangle cycles through this edge, as last counted by the
                             // cycle test (at its removal, for an edge the test rejected)
  size_t cycles_failed = 0;  // ... that did not sum to zero
  double residual = 0.0;     // measured - (o_i - o_j) with the final offsets, frames; also
                             // for rejected edges; 0 when a camera is unsynchronised
};

// The synchronised network.
struct SyncResult {
  size_t reference = 0;              // camera whose offset is fixed at 0
  std::vector<double> offsets;       // per camera, frames (o_i); 0 for unsynchronised cameras
  std::vector<double> sigmas;        // per camera, standard deviation of o_i - o_reference from
                                     // the solution, frames; 0 for the reference and unsynchronised
  std::vector<bool> synchronised;    // false for cameras not connected to the reference
  std::vector<std::string> reasons;  // why a camera is not synchronised; empty otherwise
  std::vector<SyncEdgeResult> edges;  // one per input edge, in input order
  double rms_residual = 0.0;          // over used edges, frames
  double rms_normalised = 0.0;        // over used edges, residual / sigma
};

// Synchronises `cameras` cameras from the edges. The reference is the lowest-numbered camera
// of the largest connected component (after outlier removal), and cameras outside that
// component are reported unsynchronised with a reason. Throws CheckError for an edge with an
// index out of range, i == j, a non-positive sigma or a non-finite value, and for options
// out of range (cycle_sigmas or residual_sigmas not positive, cycle_min_frames negative,
// outlier_fraction outside [0, 1]).
SyncResult SynchroniseNetwork(size_t cameras, const std::vector<OffsetEdge>& edges,
                              const SyncOptions& options = {});

}  // namespace silnet::aggregator
