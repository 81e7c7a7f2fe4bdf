#include "shared/silhouette/douglas_peucker.h"

#include <cmath>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "shared/util/check.h"

namespace silnet {
namespace {

// Squared distance from `from`, as OpenCV computes it: float differences, summed squares in
// double.
struct SquaredDistance {
  cv::Point2f from;

  double One(const cv::Point2f& p) const {
    const double dx = p.x - from.x, dy = p.y - from.y;
    return dx * dx + dy * dy;
  }
#if defined(__SSE2__)
  // The distances of the two points stored at p (x0 y0 x1 y1), bit for bit One's.
  __m128d Two(const float* p) const {
    const __m128 d = _mm_sub_ps(_mm_loadu_ps(p), _mm_setr_ps(from.x, from.y, from.x, from.y));
    const __m128d d0 = _mm_cvtps_pd(d), d1 = _mm_cvtps_pd(_mm_movehl_ps(d, d));
    const __m128d s0 = _mm_mul_pd(d0, d0), s1 = _mm_mul_pd(d1, d1);
    return _mm_add_pd(_mm_unpacklo_pd(s0, s1), _mm_unpackhi_pd(s0, s1));
  }
#endif
};

// How far a point lies from the chord from `from` along (dx, dy), times the chord's length:
// OpenCV's split measure, |(y - from.y) dx - (x - from.x) dy| with float differences.
struct ChordDistance {
  cv::Point2f from;
  double dx, dy;

  double One(const cv::Point2f& p) const {
    return std::fabs((p.y - from.y) * dx - (p.x - from.x) * dy);
  }
#if defined(__SSE2__)
  __m128d Two(const float* p) const {
    const __m128 d = _mm_sub_ps(_mm_loadu_ps(p), _mm_setr_ps(from.x, from.y, from.x, from.y));
    const __m128d d0 = _mm_cvtps_pd(d), d1 = _mm_cvtps_pd(_mm_movehl_ps(d, d));
    const __m128d x = _mm_unpacklo_pd(d0, d1), y = _mm_unpackhi_pd(d0, d1);
    const __m128d cross =
        _mm_sub_pd(_mm_mul_pd(y, _mm_set1_pd(dx)), _mm_mul_pd(x, _mm_set1_pd(dy)));
    return _mm_andnot_pd(_mm_set1_pd(-0.0), cross);
  }
#endif
};

// The first of the largest positive measures met visiting `n` ring points from index `first`
// (wrapping): OpenCV's scans, where only a strictly larger value replaces the best. `index` is
// -1 when no measure is positive.
struct Farthest {
  double distance = 0;
  int index = -1;
};

template <class Measure>
Farthest FirstLargest(const std::vector<cv::Point2f>& ring, int first, int n,
                      const Measure& measure) {
  const int count = static_cast<int>(ring.size());
  double best = 0;
  int best_order = -1;  // the best's place in the visit
  int order = 0;
  auto scan = [&](int begin, int end) {  // ring indexes [begin, end), in order
    int k = begin;
#if defined(__SSE2__)
    // Each lane keeps its first largest; the lanes merged by value, then by the earlier place.
    __m128d lane_best = _mm_setzero_pd(), lane_order = _mm_set1_pd(-1);
    __m128d orders = _mm_setr_pd(order, order + 1);
    for (; k + 2 <= end; k += 2) {
      const __m128d value = measure.Two(&ring[static_cast<size_t>(k)].x);
      const __m128d larger = _mm_cmpgt_pd(value, lane_best);
      lane_best = _mm_or_pd(_mm_and_pd(larger, value), _mm_andnot_pd(larger, lane_best));
      lane_order = _mm_or_pd(_mm_and_pd(larger, orders), _mm_andnot_pd(larger, lane_order));
      orders = _mm_add_pd(orders, _mm_set1_pd(2));
    }
    const double v0 = _mm_cvtsd_f64(lane_best),
                 v1 = _mm_cvtsd_f64(_mm_unpackhi_pd(lane_best, lane_best));
    const double o0 = _mm_cvtsd_f64(lane_order),
                 o1 = _mm_cvtsd_f64(_mm_unpackhi_pd(lane_order, lane_order));
    const bool second = v1 > v0 || (v1 == v0 && o1 < o0);
    const double lane_max = second ? v1 : v0;
    if (lane_max > best) {
      best = lane_max;
      best_order = static_cast<int>(second ? o1 : o0);
    }
    order += k - begin;
#endif
    for (; k < end; ++k, ++order) {
      const double v = measure.One(ring[static_cast<size_t>(k)]);
      if (v > best) {
        best = v;
        best_order = order;
      }
    }
  };
  const int head = std::min(n, count - first);
  scan(first, first + head);
  scan(0, n - head);
  if (best_order < 0) return {};
  return {best, (first + best_order) % count};
}

// A run of the ring from `start` to `end` (indexes, wrapping), as OpenCV's stack holds it.
struct Slice {
  int start = 0, end = 0;
};

// OpenCV's last pass: drops a point that lies nearly on the segment between its neighbours
// (`eps` the squared tolerance), walking the closed ring once from its last point.
int DropStraightCorners(std::vector<cv::Point2f>& points, double eps) {
  const int count = static_cast<int>(points.size());
  int new_count = count;
  auto next = [count](int i) { return i + 1 >= count ? 0 : i + 1; };
  int pos = count - 1;
  cv::Point2f start = points[static_cast<size_t>(pos)];
  pos = next(pos);
  int wpos = pos;
  cv::Point2f pt = points[static_cast<size_t>(pos)];
  pos = next(pos);
  for (int i = 0; i < count && new_count > 2; ++i) {
    const cv::Point2f end = points[static_cast<size_t>(pos)];
    pos = next(pos);
    const double dx = end.x - start.x, dy = end.y - start.y;
    const double dist = std::fabs((pt.x - start.x) * dy - (pt.y - start.y) * dx);
    const double inner = (pt.x - start.x) * (end.x - pt.x) + (pt.y - start.y) * (end.y - pt.y);
    if (dist * dist <= 0.5 * eps * (dx * dx + dy * dy) && dx != 0 && dy != 0 && inner >= 0) {
      --new_count;
      points[static_cast<size_t>(wpos)] = start = end;
      wpos = next(wpos);
      pt = points[static_cast<size_t>(pos)];
      pos = next(pos);
      ++i;
      continue;
    }
    points[static_cast<size_t>(wpos)] = start = pt;
    wpos = next(wpos);
    pt = end;
  }
  return new_count;
}

}  // namespace

std::vector<cv::Point2f> SimplifyClosedRing(const std::vector<cv::Point2f>& ring,
                                            double tolerance) {
  SILNET_CHECK_MSG(tolerance >= 0.0 && tolerance < 1e30, "tolerance " << tolerance);
  const int count = static_cast<int>(ring.size());
  std::vector<cv::Point2f> out;
  if (count == 0) return out;
  const double eps = tolerance * tolerance;
  auto next = [count](int i) { return i + 1 >= count ? 0 : i + 1; };
  // 1. An approximately farthest pair: three times the farthest point from the last one.
  int pos = 0, far = 0;
  bool within = false;
  cv::Point2f start;
  for (int i = 0; i < 3; ++i) {
    pos = (pos + far) % count;
    start = ring[static_cast<size_t>(pos)];
    const Farthest f = FirstLargest(ring, next(pos), count - 1, SquaredDistance{start});
    if (f.index >= 0) far = (f.index - pos + count) % count;
    within = f.distance <= eps;
  }
  // 2. Both halves of the ring between them on the stack, the first on top.
  std::vector<Slice> stack;
  if (within) {
    out.push_back(start);
  } else {
    const int other = (far + pos) % count;
    stack.push_back({other, pos});
    stack.push_back({pos, other});
  }
  // 3. Split each slice at its farthest point from the chord until all lie within tolerance.
  int split = 0;
  while (!stack.empty()) {
    const Slice slice = stack.back();
    stack.pop_back();
    const cv::Point2f end = ring[static_cast<size_t>(slice.end)];
    const cv::Point2f from = ring[static_cast<size_t>(slice.start)];
    const int first = next(slice.start);
    bool keep_whole = true;
    if (first != slice.end) {
      const double dx = end.x - from.x, dy = end.y - from.y;
      SILNET_CHECK_MSG(dx != 0 || dy != 0, "Douglas-Peucker split between equal points");
      const int n = (slice.end - first + count) % count;
      const Farthest f = FirstLargest(ring, first, n, ChordDistance{from, dx, dy});
      if (f.index >= 0) split = f.index;
      keep_whole = f.distance * f.distance <= eps * (dx * dx + dy * dy);
    }
    if (keep_whole) {
      out.push_back(from);
    } else {
      stack.push_back({split, slice.end});
      stack.push_back({slice.start, split});
    }
  }
  // 4. The last pass over nearly straight corners.
  out.resize(static_cast<size_t>(DropStraightCorners(out, eps)));
  return out;
}

}  // namespace silnet
