#include "aggregator/stereo/hull_two_colouring.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <queue>
#include <unordered_set>

#include "aggregator/stereo/hull_view_edges.h"
#include "aggregator/stereo/rim_graph.h"

namespace silnet::aggregator {
namespace {

// A mesh vertex's neighbours and the keys of the edges to them.
using Adjacency = std::vector<std::vector<std::pair<int, uint64_t>>>;

Adjacency MeshAdjacency(size_t vertices, const HullViewEdges& edges) {
  Adjacency adjacency(vertices);
  for (const auto& [key, pair] : edges.edge_triangles) {
    const int a = static_cast<int>(key & 0xffffffffu), b = static_cast<int>(key >> 32);
    adjacency[static_cast<size_t>(a)].emplace_back(b, key);
    adjacency[static_cast<size_t>(b)].emplace_back(a, key);
  }
  return adjacency;
}

// Distance in pixels from each pixel centre to the nearest pixel of the silhouette's outline
// (silhouette pixels with a background 4-neighbour).
cv::Mat OutlineDistance(const cv::Mat& mask) {
  cv::Mat inside = mask != 0, eroded;
  cv::erode(inside, eroded, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)));
  cv::Mat not_outline = ~(inside & ~eroded);
  cv::Mat distance;
  cv::distanceTransform(not_outline, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance;
}

// Eq. 6.1: the squared outline distance integrated along the edge a-b's image in one view, in
// pixels (sampled at most a pixel apart), plus `epsilon`.
double CurveEdgeWeight(const CameraModel& camera, const cv::Mat& distance, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double epsilon) {
  const auto pa = camera.Project(a), pb = camera.Project(b);
  if (!pa || !pb) return std::numeric_limits<double>::infinity();
  const double length = (*pb - *pa).norm();
  const int samples = std::max(1, static_cast<int>(std::ceil(length)));
  double sum = 0;
  for (int k = 0; k < samples; ++k) {
    const Eigen::Vector2d x = *pa + (*pb - *pa) * ((k + 0.5) / samples);
    const int u = std::clamp(static_cast<int>(std::lround(x.x())), 0, distance.cols - 1);
    const int v = std::clamp(static_cast<int>(std::lround(x.y())), 0, distance.rows - 1);
    const double d = distance.at<float>(v, u);
    sum += d * d;
  }
  return sum * length / samples + epsilon;
}

// The shortest path (Dijkstra) from any of `sources` to any of `targets` over the edges
// `allowed` accepts, weighted by `weight`; empty if none joins them.
template <typename Allowed, typename Weight>
std::vector<int> ShortestPath(const Adjacency& adjacency, const std::vector<int>& sources,
                              const std::vector<int>& targets, Allowed allowed, Weight weight) {
  std::vector<double> dist(adjacency.size(), std::numeric_limits<double>::infinity());
  std::vector<int> from(adjacency.size(), -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (const int s : sources) {
    dist[static_cast<size_t>(s)] = 0;
    queue.emplace(0.0, s);
  }
  const std::unordered_set<int> goal(targets.begin(), targets.end());
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[static_cast<size_t>(v)]) continue;
    if (goal.count(v) > 0) {
      std::vector<int> path;
      for (int at = v; at >= 0; at = from[static_cast<size_t>(at)])
        path.push_back(at);
      return path;
    }
    for (const auto& [w, key] : adjacency[static_cast<size_t>(v)]) {
      if (!allowed(key)) continue;
      const double next = d + weight(v, w);
      if (next < dist[static_cast<size_t>(w)]) {
        dist[static_cast<size_t>(w)] = next;
        from[static_cast<size_t>(w)] = v;
        queue.emplace(next, w);
      }
    }
  }
  return {};
}

// The vertices reachable from `seeds` over the edges `open` accepts without entering a
// `blocked` vertex.
template <typename Open>
std::vector<bool> Reach(const Adjacency& adjacency, const std::vector<int>& seeds,
                        const std::vector<bool>& blocked, Open open) {
  std::vector<bool> reached(adjacency.size(), false);
  std::deque<int> queue;
  for (const int v : seeds) {
    if (blocked[static_cast<size_t>(v)] || reached[static_cast<size_t>(v)]) continue;
    reached[static_cast<size_t>(v)] = true;
    queue.push_back(v);
  }
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    for (const auto& [w, key] : adjacency[static_cast<size_t>(v)]) {
      if (blocked[static_cast<size_t>(w)] || reached[static_cast<size_t>(w)] || !open(key))
        continue;
      reached[static_cast<size_t>(w)] = true;
      queue.push_back(w);
    }
  }
  return reached;
}

// The hull and what the colouring derives from it once.
struct HullGraph {
  const TriangleMesh& hull;
  const HullProvenance& provenance;
  std::vector<Eigen::Vector3d> centres;  // per view
  HullViewEdges edges;
  Adjacency adjacency;
  std::vector<std::vector<int>> vertex_triangles;

  Eigen::Vector3d Position(int v) const {
    return hull.vertices[static_cast<size_t>(v)].cast<double>();
  }
  int ViewOfTriangle(int t) const {
    const int plane = edges.triangle_plane[static_cast<size_t>(t)];
    return plane < 0 ? -1 : provenance.planes[static_cast<size_t>(plane)].view;
  }
  // True if edge `key` lies between two triangles of `view`'s strip.
  bool InsideStrip(uint64_t key, int view) const {
    for (const int t : edges.edge_triangles.at(key)) {
      if (t < 0 || ViewOfTriangle(t) != view) return false;
    }
    return true;
  }
  // Whether the hull faces camera `view` at vertex v: its triangles off the view's strip (those
  // are edge-on), area-weighted.
  bool FacesCamera(int view, int v) const {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (const int t : vertex_triangles[static_cast<size_t>(v)]) {
      if (ViewOfTriangle(t) == view) continue;
      const auto& tri = hull.triangles[static_cast<size_t>(t)];
      normal += (Position(tri[1]) - Position(tri[0])).cross(Position(tri[2]) - Position(tri[0]));
    }
    return normal.dot(centres[static_cast<size_t>(view)] - Position(v)) > 0;
  }
};

// Step 2 for one view: the connecting curves across its strip's discontinuities; their
// vertices (the view's rim vertices) marked in the result.
std::vector<bool> ConnectingCurves(const HullGraph& graph, int view, const TrueSegments& chosen,
                                   const CameraModel& camera, const cv::Mat& mask,
                                   const HullColouringOptions& options, HullColouringStats& stats) {
  std::vector<bool> rim(graph.hull.vertices.size(), false);
  const bool has_break =
      std::any_of(chosen.breaks.begin(), chosen.breaks.end(), [&](const auto& b) {
        return graph.edges.segments[static_cast<size_t>(b.first)].view == view;
      });
  if (!has_break) return rim;  // a whole strip: no distance map needed
  const cv::Mat distance = OutlineDistance(mask);
  // Off the inside of the strip: a viewing-edge end has no other edge than its strip's boundary.
  const auto allowed = [&](uint64_t key) { return !graph.InsideStrip(key, view); };
  const auto weight = [&](int a, int b) {
    return CurveEdgeWeight(camera, distance, graph.Position(a), graph.Position(b),
                           options.curve_epsilon);
  };
  for (const auto& [a, b] : chosen.breaks) {
    const ViewEdgeSegment& from = graph.edges.segments[static_cast<size_t>(a)];
    if (from.view != view) continue;
    const ViewEdgeSegment& to = graph.edges.segments[static_cast<size_t>(b)];
    const std::vector<int> path = ShortestPath(graph.adjacency, {from.near_vertex, from.far_vertex},
                                               {to.near_vertex, to.far_vertex}, allowed, weight);
    ++stats.connecting_curves;
    if (path.empty()) ++stats.unconnected;
    for (const int v : path)
      rim[static_cast<size_t>(v)] = true;
  }
  return rim;
}

// Step 3 for one view: front (1) and back (0) reached from the true segments' ends around the
// repaired strip (its pieces between true segments, the true segments, the `rim` vertices);
// where both reach, the hull's facing; -1 on rim vertices and where neither reaches.
std::vector<int8_t> SideLabels(const HullGraph& graph, int view, const TrueSegments& chosen,
                               const std::unordered_set<int>& strip_pieces,
                               const std::vector<bool>& rim, HullColouringStats& stats) {
  std::vector<int> front_seeds, back_seeds;
  std::unordered_set<uint64_t> true_edges;
  for (size_t s = 0; s < graph.edges.segments.size(); ++s) {
    const ViewEdgeSegment& segment = graph.edges.segments[s];
    if (segment.view != view || !chosen.is_true[s]) continue;
    true_edges.insert(segment.edges.begin(), segment.edges.end());
    // A true segment on no strip piece (discontinuities on both sides) is only a stretch of the
    // barrier's curve: its ends need not lie on the strip's two sides.
    const bool on_strip = std::any_of(segment.pieces.begin(), segment.pieces.end(),
                                      [&](int piece) { return strip_pieces.count(piece) > 0; });
    if (!on_strip) continue;
    front_seeds.push_back(segment.near_vertex);
    back_seeds.push_back(segment.far_vertex);
  }
  const auto open = [&](uint64_t key) {
    if (true_edges.count(key) > 0) return false;
    for (const int t : graph.edges.edge_triangles.at(key)) {
      if (t < 0 || graph.ViewOfTriangle(t) != view ||
          strip_pieces.count(graph.edges.triangle_piece[static_cast<size_t>(t)]) == 0)
        return true;
    }
    return false;
  };
  const std::vector<bool> front = Reach(graph.adjacency, front_seeds, rim, open);
  const std::vector<bool> back = Reach(graph.adjacency, back_seeds, rim, open);
  std::vector<int8_t> labels(rim.size(), -1);
  for (size_t v = 0; v < labels.size(); ++v) {
    if (rim[v]) continue;
    if (front[v] && back[v]) {
      // Both sides meet here across a rim the hull does not show (hidden behind another part,
      // thesis 6.4): the hull's own facing decides.
      labels[v] = graph.FacesCamera(view, static_cast<int>(v)) ? 1 : 0;
      ++stats.hidden_rim;
    } else if (front[v] || back[v]) {
      labels[v] = front[v] ? 1 : 0;
    } else {
      ++stats.unlabelled;
    }
  }
  return labels;
}

// Step 4: the parity of the front labels, green where a view left the vertex undecided.
std::vector<HullVertexColour> ParityColours(const std::vector<std::vector<int8_t>>& labels,
                                            const std::vector<bool>& any_rim, size_t* green) {
  std::vector<HullVertexColour> colours(any_rim.size(), HullVertexColour::kRed);
  for (size_t v = 0; v < colours.size(); ++v) {
    int fronts = 0;
    bool undecided = any_rim[v];
    for (const std::vector<int8_t>& view : labels) {
      undecided = undecided || view[v] < 0;
      fronts += view[v] == 1 ? 1 : 0;
    }
    if (undecided) {
      colours[v] = HullVertexColour::kGreen;
      ++*green;
    } else {
      colours[v] = fronts % 2 == 0 ? HullVertexColour::kRed : HullVertexColour::kBlue;
    }
  }
  return colours;
}

}  // namespace

HullColouring ColourHullVertices(const TriangleMesh& hull, const HullProvenance& provenance,
                                 const std::vector<CameraModel>& cameras,
                                 const std::vector<cv::Mat>& masks,
                                 const SegmentPhotoConsistency& photo_consistency,
                                 const HullColouringOptions& options) {
  const size_t views = provenance.view_cameras.size();
  const auto camera_index = [&](size_t view) {
    return static_cast<size_t>(provenance.view_cameras[view]);
  };
  HullGraph graph{hull, provenance, {}, {}, {}, {}};
  for (size_t view = 0; view < views; ++view)
    graph.centres.push_back(cameras[camera_index(view)].Center());
  graph.edges = FindHullViewEdges(hull, provenance, graph.centres);
  graph.adjacency = MeshAdjacency(hull.vertices.size(), graph.edges);
  graph.vertex_triangles.resize(hull.vertices.size());
  for (size_t t = 0; t < hull.triangles.size(); ++t) {
    for (const int v : hull.triangles[t])
      graph.vertex_triangles[static_cast<size_t>(v)].push_back(static_cast<int>(t));
  }

  HullColouring colouring;
  HullColouringStats& stats = colouring.stats;
  stats.segments = graph.edges.segments.size();
  std::vector<double> weight;
  for (const ViewEdgeSegment& segment : graph.edges.segments)
    weight.push_back(1 - photo_consistency(graph.Position(segment.near_vertex),
                                           graph.Position(segment.far_vertex)));
  const TrueSegments chosen =
      ChooseTrueSegments(graph.edges, provenance.planes, weight, options.discontinuity_cost);
  stats.false_segments =
      static_cast<size_t>(std::count(chosen.is_true.begin(), chosen.is_true.end(), false));
  const std::unordered_set<int> strip_pieces(chosen.strip_pieces.begin(),
                                             chosen.strip_pieces.end());
  std::vector<bool> any_rim(hull.vertices.size(), false);
  for (size_t view = 0; view < views; ++view) {
    const int v = static_cast<int>(view);
    const std::vector<bool> rim = ConnectingCurves(graph, v, chosen, cameras[camera_index(view)],
                                                   masks[camera_index(view)], options, stats);
    colouring.labels.push_back(SideLabels(graph, v, chosen, strip_pieces, rim, stats));
    for (size_t x = 0; x < rim.size(); ++x)
      any_rim[x] = any_rim[x] || rim[x];
  }
  colouring.colours = ParityColours(colouring.labels, any_rim, &stats.green_vertices);
  return colouring;
}

}  // namespace silnet::aggregator
