// Visual hull benchmarks: one frame of 8 views at 640x480 (simulated walking person), one
// core: voxel carving at 1 cm and 2 cm, surface extraction, the exact polyhedral hull, and
// sub-frame interpolation; the exact hull of an exactly symmetric ring and of the real
// captures in the shared data folder; contour tracing and simplification against OpenCV's.
//   build/tests/bench/silnet_hulls_bench

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/hull_edges.h"
#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/real_datasets.h"
#include "aggregator/hulls/silhouette_interpolation.h"
#include "aggregator/hulls/traced_hull_mesh.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/viewing_edges.h"
#include "aggregator/hulls/voxel_hull.h"
#include "shared/geometry/camera_model.h"
#include "shared/silhouette/border_tracing.h"
#include "shared/silhouette/douglas_peucker.h"
#include "shared/silhouette/foreground_box.h"
#include "shared/silhouette/silhouette_contour.h"
#include "sim/camera_network.h"
#include "sim/render/camera_renderer.h"

namespace silnet::aggregator {
namespace {

// Eight ring cameras and their exact masks of one frame of a walking person.
struct Frame {
  std::vector<CameraModel> cameras = sim::MakeCameraNetwork(sim::CameraNetworkOptions{});
  sim::Scene scene{[] {
    sim::SceneOptions o;
    o.time_begin = -1;
    o.time_end = 30;
    return o;
  }()};
  std::vector<cv::Mat> masks;
  std::vector<cv::Mat> next_masks;

  Frame() {
    for (size_t c = 0; c < cameras.size(); ++c) {
      const sim::CameraRenderer renderer(cameras[c], scene, sim::RenderSettings{},
                                         static_cast<int>(c));
      masks.emplace_back();
      next_masks.emplace_back();
      // All views at one reference time (a synchronised frame), and one frame later.
      renderer.Render(1.0, 0, &masks.back(), nullptr);
      renderer.Render(1.0 + 1.0 / 30.0, 0, &next_masks.back(), nullptr);
    }
  }
};

const Frame& TheFrame() {
  static const Frame frame;
  return frame;
}

void BM_CarveVoxelHull8Views(benchmark::State& state) {
  const Frame& frame = TheFrame();
  VoxelHullOptions options;
  options.voxel_size = static_cast<double>(state.range(0)) / 1000.0;
  options.threads = 1;
  size_t occupied = 0;
  for (auto _ : state) {
    const VoxelHullResult hull = CarveVoxelHull(frame.cameras, frame.masks, options);
    occupied = hull.grid.CountOccupied();
    benchmark::DoNotOptimize(occupied);
  }
  state.counters["voxels"] = static_cast<double>(occupied);
}
BENCHMARK(BM_CarveVoxelHull8Views)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);

void BM_CarveAndMesh8Views(benchmark::State& state) {
  const Frame& frame = TheFrame();
  VoxelHullOptions options;
  options.voxel_size = static_cast<double>(state.range(0)) / 1000.0;
  options.threads = 1;
  size_t triangles = 0;
  for (auto _ : state) {
    const VoxelHullResult hull = CarveVoxelHull(frame.cameras, frame.masks, options);
    triangles = ExtractBoundaryMesh(hull.grid).triangles.size();
    benchmark::DoNotOptimize(triangles);
  }
  state.counters["triangles"] = static_cast<double>(triangles);
}
BENCHMARK(BM_CarveAndMesh8Views)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);

// The polyhedral hull of TheFrame with `options`; counters: the worst view's missed and extra
// silhouette pixels (percent), the mesh's triangles and the cone faces (contour edges).
void RunPolyhedralHull8Views(benchmark::State& state, const PolyhedralHullOptions& options) {
  const Frame& frame = TheFrame();
  PolyhedralHullResult hull;
  for (auto _ : state) {
    hull = ComputePolyhedralHull(frame.cameras, frame.masks, options);
    if (!hull.success) state.SkipWithError(hull.reason.c_str());
    benchmark::DoNotOptimize(hull.mesh.triangles.size());
  }
  state.counters["triangles"] = static_cast<double>(hull.mesh.triangles.size());
  state.counters["cone_faces"] = static_cast<double>(hull.stats.cone_faces);
  state.counters["traced"] = hull.stats.traced_edges ? 1 : 0;
  double missed = 0.0, extra = 0.0;
  for (const ViewReprojection& v : MeasureHullReprojection(hull.mesh, frame.cameras, frame.masks)) {
    missed = std::max(missed, v.missed_fraction);
    extra = std::max(extra, v.spurious_fraction);
  }
  state.counters["worst_view_missed_pct"] = 100.0 * missed;
  state.counters["worst_view_extra_pct"] = 100.0 * extra;
}

// Arg: contour tolerance in tenths of a pixel (6 is the default).
void BM_PolyhedralHull8Views(benchmark::State& state) {
  PolyhedralHullOptions options;
  options.contour_tolerance_px = static_cast<double>(state.range(0)) / 10.0;
  RunPolyhedralHull8Views(state, options);
}
BENCHMARK(BM_PolyhedralHull8Views)->Arg(5)->Arg(6)->Arg(10)->Unit(benchmark::kMillisecond);

// The same at the default tolerance with the face-by-face sweeps only (trace_edges off), for
// comparison in one run.
void BM_PolyhedralHull8ViewsSweeps(benchmark::State& state) {
  PolyhedralHullOptions options;
  options.trace_edges = false;
  RunPolyhedralHull8Views(state, options);
}
BENCHMARK(BM_PolyhedralHull8ViewsSweeps)->Unit(benchmark::kMillisecond);

// With covering contours (PolyhedralHullOptions::contour_cover_pixel_centres).
void BM_PolyhedralHull8ViewsCovering(benchmark::State& state) {
  PolyhedralHullOptions options;
  options.contour_cover_pixel_centres = true;
  RunPolyhedralHull8Views(state, options);
}
BENCHMARK(BM_PolyhedralHull8ViewsCovering)->Unit(benchmark::kMillisecond);

// An exactly symmetric ring (arg: cameras, evenly spaced on a 1.5 m circle, all aimed at
// a 0.2 m sphere, 320x240, principal points at the image centres): every mask is the same
// raster disc, so cone faces of several views meet at single points, where the traced edges
// do not close and the plain face-by-face sweeps, then the perturbed contours' traced edges
// take over (counters: whether the hull came from perturbed contours, gaps filled, traced or
// swept).
void BM_PolyhedralHullSymmetricRing(benchmark::State& state) {
  constexpr double kFocalPx = 300, kDistance = 1.5, kRadius = 0.2;
  const int count = static_cast<int>(state.range(0));
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  const double disc_px = kFocalPx * kRadius / std::sqrt(kDistance * kDistance - kRadius * kRadius);
  for (int c = 0; c < count; ++c) {
    const double angle = 2 * std::numbers::pi * c / count;
    const Eigen::Vector3d eye = kDistance * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0);
    CameraModel camera;
    camera.id = "cam" + std::to_string(c);
    camera.width = 320;
    camera.height = 240;
    camera.K << kFocalPx, 0, 159.5, 0, kFocalPx, 119.5, 0, 0, 1;
    camera.R = LookAtRotation(eye, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    camera.t = -camera.R * eye;
    cameras.push_back(camera);
    masks.emplace_back(240, 320, CV_8UC1, cv::Scalar(0));
    // Centre and radius in sixteenths of a pixel (cv::circle's shift of 4).
    cv::circle(masks.back(), cv::Point(159 * 16 + 8, 119 * 16 + 8),
               static_cast<int>(std::lround(16 * disc_px)), cv::Scalar(255), cv::FILLED, cv::LINE_8,
               4);
  }
  PolyhedralHullResult hull;
  for (auto _ : state) {
    hull = ComputePolyhedralHull(cameras, masks, PolyhedralHullOptions{});
    if (!hull.success) state.SkipWithError(hull.reason.c_str());
    benchmark::DoNotOptimize(hull.mesh.triangles.size());
  }
  state.counters["triangles"] = static_cast<double>(hull.mesh.triangles.size());
  state.counters["perturbed"] = hull.stats.contours_perturbed ? 1 : 0;
  state.counters["gaps_filled"] = static_cast<double>(hull.stats.gaps_filled);
  state.counters["traced"] = hull.stats.traced_edges ? 1 : 0;
}
BENCHMARK(BM_PolyhedralHullSymmetricRing)->Arg(8)->Arg(12)->Arg(16)->Unit(benchmark::kMillisecond);

// Args: 0 the INRIA dancer (8 views, 780x582), 1 Tsinghua WD2 (20 views, 1024x768); then 1
// for the default (edges traced), 0 for the face-by-face sweeps only.
void BM_PolyhedralHullRealCapture(benchmark::State& state) {
  const std::filesystem::path data = SILNET_SHARED_DATA_DIR;
  const bool wd2 = state.range(0) == 1;
  const std::filesystem::path folder =
      data / (wd2 ? "tsinghua-wd2-20cam" : "inria-dancer-silhouettes");
  if (!std::filesystem::exists(folder)) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  RealCapture capture = wd2 ? LoadTsinghuaWd2(folder, false) : LoadInriaDancer(folder);
  if (!wd2) {
    for (cv::Mat& mask : capture.masks)
      mask = KeepLargestComponent(mask);
  }
  PolyhedralHullOptions options;
  options.trace_edges = state.range(1) != 0;
  PolyhedralHullResult hull;
  for (auto _ : state) {
    hull = ComputePolyhedralHull(capture.cameras, capture.masks, options);
    if (!hull.success) state.SkipWithError(hull.reason.c_str());
    benchmark::DoNotOptimize(hull.mesh.triangles.size());
  }
  state.counters["triangles"] = static_cast<double>(hull.mesh.triangles.size());
  state.counters["cone_faces"] = static_cast<double>(hull.stats.cone_faces);
  state.counters["gaps_filled"] = static_cast<double>(hull.stats.gaps_filled);
  state.counters["traced"] = hull.stats.traced_edges ? 1 : 0;
}
BENCHMARK(BM_PolyhedralHullRealCapture)
    ->ArgsProduct({{0, 1}, {1, 0}})
    ->Unit(benchmark::kMillisecond);

// EPVH's own "alien" set (24 views, 1900x1600; issue 20), cameras 0..k-1, loaded once.
const RealCapture* Alien() {
  static const std::unique_ptr<RealCapture> capture = [] {
    const std::filesystem::path folder =
        std::filesystem::path(SILNET_SHARED_DATA_DIR) / "epvh-alien-24cam";
    return std::filesystem::exists(folder) ? std::make_unique<RealCapture>(LoadEpvhAlien(folder))
                                           : nullptr;
  }();
  return capture.get();
}

// The exact hull of alien cameras 0..views-1 from masks, everything included (contours, cone
// bounds, faces, mesh), on `threads` threads, edges traced or (`trace` false) the face-by-face
// sweeps only.
void RunPolyhedralHullAlien(benchmark::State& state, long views, int threads, bool trace) {
  const RealCapture* alien = Alien();
  if (!alien) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  const std::vector<CameraModel> cameras(alien->cameras.begin(), alien->cameras.begin() + views);
  const std::vector<cv::Mat> masks(alien->masks.begin(), alien->masks.begin() + views);
  PolyhedralHullOptions options;
  options.threads = threads;
  options.trace_edges = trace;
  PolyhedralHullResult hull;
  for (auto _ : state) {
    hull = ComputePolyhedralHull(cameras, masks, options);
    if (!hull.success) state.SkipWithError(hull.reason.c_str());
    benchmark::DoNotOptimize(hull.mesh.triangles.size());
  }
  state.counters["triangles"] = static_cast<double>(hull.mesh.triangles.size());
  state.counters["cone_faces"] = static_cast<double>(hull.stats.cone_faces);
  state.counters["traced"] = hull.stats.traced_edges ? 1 : 0;
}

// Args: views, then 1 for the default (edges traced), 0 for the face-by-face sweeps only. One
// thread, as EPVH's figures in docs/PERFORMANCE.md.
void BM_PolyhedralHullAlien(benchmark::State& state) {
  RunPolyhedralHullAlien(state, static_cast<long>(state.range(0)), 1, state.range(1) != 0);
}
BENCHMARK(BM_PolyhedralHullAlien)
    ->ArgsProduct({{4, 8, 12, 16}, {1, 0}})
    ->Unit(benchmark::kMillisecond);

// Args: views, threads (cone faces and contours in parallel).
void BM_PolyhedralHullAlienThreads(benchmark::State& state) {
  RunPolyhedralHullAlien(state, static_cast<long>(state.range(0)), static_cast<int>(state.range(1)),
                         true);
}
BENCHMARK(BM_PolyhedralHullAlienThreads)
    ->Args({8, 1})
    ->Args({8, 2})
    ->Args({16, 1})
    ->Args({16, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The contour options of the exact hull from masks at its defaults.
ContourOptions HullContourOptions() {
  const PolyhedralHullOptions defaults;
  ContourOptions options;
  options.tolerance_px = defaults.contour_tolerance_px;
  options.smoothing_passes = defaults.contour_smoothing_passes;
  options.boundary_offset_px = defaults.contour_offset_px;
  return options;
}

// Arg: views. Only the contour extraction of the above (default options), to split its cost.
void BM_AlienContours(benchmark::State& state) {
  const RealCapture* alien = Alien();
  if (!alien) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  const ContourOptions options = HullContourOptions();
  size_t points = 0;
  for (auto _ : state) {
    points = 0;
    for (long v = 0; v < state.range(0); ++v)
      points +=
          ExtractContours(alien->masks[static_cast<size_t>(v)], options).polygons[0].outer.size();
    benchmark::DoNotOptimize(points);
  }
  state.counters["contour_points"] = static_cast<double>(points);
}
BENCHMARK(BM_AlienContours)->Arg(4)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);

// Args: views, stages. The exact hull of the alien's cameras 0..views-1 as issue 20's
// restructure builds it, one thread, from the contours and cone planes the polyhedral hull
// builds at its defaults (prepared outside the loop): stage 0 the viewing edges once per
// contour vertex (aggregator/hulls/viewing_edges.h), 1 also the edges traced from them
// (hull_edges.h), 2 also the mesh of the faces' loops (traced_hull_mesh.h).
void BM_TracedHullAlien(benchmark::State& state) {
  const RealCapture* alien = Alien();
  if (!alien) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  const auto views = static_cast<size_t>(state.range(0));
  const std::vector<CameraModel> cameras(alien->cameras.begin(), alien->cameras.begin() + views);
  const std::vector<cv::Mat> masks(alien->masks.begin(), alien->masks.begin() + views);
  std::vector<SilhouetteContours> contours;
  for (const cv::Mat& mask : masks)
    contours.push_back(ExtractContours(mask, HullContourOptions()));
  WorldBox box = ComputeViewingConeBounds(cameras, masks).box;
  const Eigen::Vector3d pad = PolyhedralHullOptions{}.bounds_padding * box.sizes();
  box.min() -= pad;
  box.max() += pad;
  const ConePlaneSet set(cameras, contours, box);
  const int64_t stages = state.range(1);
  size_t edges = 0, vertices = 0, triangles = 0;
  for (auto _ : state) {
    const std::vector<ViewingEdge> viewing = ComputeViewingEdges(cameras, set, box);
    edges = viewing.size();
    if (stages >= 1) {
      const HullEdgeGraph graph = TraceHullEdges(cameras, set, box, viewing);
      edges = graph.edges.size();
      vertices = graph.vertices.size();
      if (stages >= 2) {
        const TracedHullMesh mesh = AssembleTracedHull(set, graph);
        if (!mesh.success) state.SkipWithError(mesh.reason.c_str());
        triangles = mesh.mesh.triangles.size();
      }
    }
    benchmark::DoNotOptimize(edges);
  }
  state.counters["rays"] = static_cast<double>(set.Planes().size());
  state.counters["edges"] = static_cast<double>(edges);
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["triangles"] = static_cast<double>(triangles);
}
BENCHMARK(BM_TracedHullAlien)->ArgsProduct({{8, 16}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

// The foreground's box of the alien's 8 masks (1900x1600): the margin scan (arg 0) against
// OpenCV's full scan (arg 1).
void BM_AlienForegroundBox(benchmark::State& state) {
  const RealCapture* alien = Alien();
  if (!alien) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  for (auto _ : state) {
    for (size_t v = 0; v < 8; ++v) {
      const cv::Mat& mask = alien->masks[v];
      benchmark::DoNotOptimize(state.range(0) == 0 ? ForegroundBox(mask) : cv::boundingRect(mask));
    }
  }
}
BENCHMARK(BM_AlienForegroundBox)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The masks of the contour benchmarks below: 0 the INRIA dancer's 8 views (largest component
// kept, as the hull benchmark above), 1 the alien's cameras 0-7; nullptr without the data.
const std::vector<cv::Mat>* ContourBenchMasks(int64_t which) {
  static const std::unique_ptr<std::vector<cv::Mat>> dancer = [] {
    const std::filesystem::path folder =
        std::filesystem::path(SILNET_SHARED_DATA_DIR) / "inria-dancer-silhouettes";
    if (!std::filesystem::exists(folder)) return std::unique_ptr<std::vector<cv::Mat>>();
    auto masks = std::make_unique<std::vector<cv::Mat>>(LoadInriaDancer(folder).masks);
    for (cv::Mat& mask : *masks)
      mask = KeepLargestComponent(mask);
    return masks;
  }();
  if (which == 0) return dancer.get();
  const RealCapture* alien = Alien();
  if (!alien) return nullptr;
  static const std::vector<cv::Mat> alien8(alien->masks.begin(), alien->masks.begin() + 8);
  return &alien8;
}

// Args: masks (as above), tracer (0 silnet's TraceBorders, 1 OpenCV's findContours; the same
// rings): the borders inside each mask's foreground box, as contour extraction traces them.
void BM_BorderTracing(benchmark::State& state) {
  const std::vector<cv::Mat>* masks = ContourBenchMasks(state.range(0));
  if (!masks) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  std::vector<cv::Rect> boxes;
  for (const cv::Mat& mask : *masks)
    boxes.push_back(ForegroundBox(mask));
  std::vector<std::vector<cv::Point>> rings;
  std::vector<cv::Vec4i> hierarchy;
  for (auto _ : state) {
    for (size_t v = 0; v < boxes.size(); ++v) {
      const cv::Mat& mask = (*masks)[v];
      if (state.range(1) == 0) {
        TraceBorders(mask, boxes[v], rings, hierarchy);
      } else {
        cv::findContours(mask(boxes[v]), rings, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE,
                         boxes[v].tl());
      }
      benchmark::DoNotOptimize(rings.data());
    }
  }
}
BENCHMARK(BM_BorderTracing)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMicrosecond);

// Args: masks, simplification (0 silnet's SimplifyClosedRing, 1 OpenCV's approxPolyDP; the
// same points): the traced rings, smoothed once as the hull's contours are, simplified at the
// hull's default tolerance.
void BM_RingSimplification(benchmark::State& state) {
  const std::vector<cv::Mat>* masks = ContourBenchMasks(state.range(0));
  if (!masks) {
    state.SkipWithError("no real data beside the project");
    return;
  }
  std::vector<std::vector<cv::Point2f>> smoothed;
  for (const cv::Mat& mask : *masks) {
    std::vector<std::vector<cv::Point>> rings;
    cv::findContours(mask, rings, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
    for (const std::vector<cv::Point>& ring : rings) {
      const size_t n = ring.size();
      std::vector<cv::Point2f>& out = smoothed.emplace_back(n);
      for (size_t i = 0; i < n; ++i) {
        out[i] = 0.25f * (cv::Point2f(ring[(i + n - 1) % n]) + cv::Point2f(ring[(i + 1) % n])) +
                 0.5f * cv::Point2f(ring[i]);
      }
    }
  }
  const double tolerance = PolyhedralHullOptions{}.contour_tolerance_px;
  size_t points = 0;
  std::vector<cv::Point2f> simplified;
  for (auto _ : state) {
    points = 0;
    for (const std::vector<cv::Point2f>& ring : smoothed) {
      if (state.range(1) == 0) {
        simplified = SimplifyClosedRing(ring, tolerance);
      } else {
        cv::approxPolyDP(ring, simplified, tolerance, true);
      }
      points += simplified.size();
    }
    benchmark::DoNotOptimize(points);
  }
  size_t traced = 0;
  for (const std::vector<cv::Point2f>& ring : smoothed)
    traced += ring.size();
  state.counters["ring_points"] = static_cast<double>(traced);
  state.counters["kept_points"] = static_cast<double>(points);
}
BENCHMARK(BM_RingSimplification)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMicrosecond);

void BM_InterpolateSilhouette640x480(benchmark::State& state) {
  const Frame& frame = TheFrame();
  for (auto _ : state)
    benchmark::DoNotOptimize(InterpolateSilhouette(frame.masks[0], frame.next_masks[0], 0.4));
}
BENCHMARK(BM_InterpolateSilhouette640x480)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace silnet::aggregator

BENCHMARK_MAIN();
