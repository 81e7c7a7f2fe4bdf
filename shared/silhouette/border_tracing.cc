#include "shared/silhouette/border_tracing.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <opencv2/imgproc.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "shared/util/check.h"

namespace silnet {
namespace {

// The marks OpenCV's tracer leaves: each border's label (2, 3, ... in the order borders are
// found, at most 127) on the foreground pixels it passes first, with the high bit where the
// pixel to the right is background the follower examined. The scan reads them back.
constexpr int kFirstLabel = 2, kLastLabel = 127;
constexpr int kRightBound = 0x80;

// Chain code directions: 0 right, then counterclockwise on screen (y down) in 45° steps.
constexpr std::array<int, 8> kStepX = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr std::array<int, 8> kStepY = {0, -1, -1, -1, 0, 1, 1, 1};

// The box of a mask with a one pixel background frame around it, foreground 1 and background
// 0, row after row; 16 bytes of slack after the last row for wide reads.
class FramedMask {
 public:
  FramedMask(const cv::Mat& mask, const cv::Rect& box)
      : cols_(box.width + 2),
        rows_(box.height + 2),
        pixels_(std::make_unique_for_overwrite<int8_t[]>(
            static_cast<size_t>(cols_) * static_cast<size_t>(rows_) + kSlack)) {
    std::memset(Row(0), 0, static_cast<size_t>(cols_));
    std::memset(Row(rows_ - 1), 0, static_cast<size_t>(cols_) + kSlack);
    for (int y = 0; y < box.height; ++y) {
      int8_t* row = Row(y + 1);
      row[0] = 0;
      row[cols_ - 1] = 0;
      CopyAsBits(mask.ptr<uint8_t>(box.y + y) + box.x, box.width, row + 1);
    }
  }

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  int8_t* Row(int y) { return pixels_.get() + static_cast<ptrdiff_t>(y) * cols_; }

 private:
  static constexpr size_t kSlack = 16;

  // to[x] = from[x] != 0 for x in [0, n).
  static void CopyAsBits(const uint8_t* from, int n, int8_t* to) {
    int x = 0;
#if defined(__SSE2__)
    if (n >= 16) {
      const __m128i one = _mm_set1_epi8(1);
      auto copy16 = [&](int at) {
        const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(from + at));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(to + at), _mm_min_epu8(bytes, one));
      };
      for (; x + 16 <= n; x += 16)
        copy16(x);
      if (x < n) copy16(n - 16);  // the rest, overlapping what is done
      return;
    }
#endif
    for (; x < n; ++x)
      to[x] = from[x] != 0 ? 1 : 0;
  }

  int cols_, rows_;
  std::unique_ptr<int8_t[]> pixels_;
};

// The first x in [x, end) with row[x] != value, or end; may read up to 15 bytes past end.
int NextChange(const int8_t* row, int x, int end, int8_t value) {
#if defined(__SSE2__)
  const __m128i same = _mm_set1_epi8(value);
  for (; x < end; x += 16) {
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + x));
    const auto differ =
        static_cast<unsigned>(~_mm_movemask_epi8(_mm_cmpeq_epi8(bytes, same))) & 0xFFFFu;
    if (differ != 0) return std::min(end, x + std::countr_zero(differ));
  }
  return end;
#else
  while (x < end && row[x] == value)
    ++x;
  return x;
#endif
}

// Bit k set where the neighbour of `p` in direction k is foreground (marked or not).
unsigned ForegroundNeighbours(const int8_t* p, ptrdiff_t step) {
  return static_cast<unsigned>(p[1] != 0) | static_cast<unsigned>(p[1 - step] != 0) << 1 |
         static_cast<unsigned>(p[-step] != 0) << 2 | static_cast<unsigned>(p[-1 - step] != 0) << 3 |
         static_cast<unsigned>(p[-1] != 0) << 4 | static_cast<unsigned>(p[step - 1] != 0) << 5 |
         static_cast<unsigned>(p[step] != 0) << 6 | static_cast<unsigned>(p[step + 1] != 0) << 7;
}

// Follows the border through `origin` (an outer border's first pixel, or for a hole the
// foreground pixel left of its first background pixel) as OpenCV's follower does: marks its
// pixels with `label` and appends them, `at` being the origin's output coordinates.
void FollowBorder(int8_t* origin, ptrdiff_t step, cv::Point at, bool hole, int label,
                  std::vector<cv::Point>& ring) {
  const std::array<ptrdiff_t, 8> delta = {1,  1 - step, -step, -1 - step,
                                          -1, step - 1, step,  step + 1};
  const auto mark = static_cast<int8_t>(label),
             right_bound = static_cast<int8_t>(label | kRightBound);
  // The first foreground neighbour clockwise from the side the scan came from.
  const int start = hole ? 0 : 4;
  int s = start;
  int8_t* second = nullptr;
  do {
    s = (s - 1) & 7;
    second = origin + delta[static_cast<size_t>(s)];
  } while (*second == 0 && s != start);
  if (s == start) {  // a lone pixel
    *origin = right_bound;
    ring.push_back(at);
    return;
  }
  int8_t* here = origin;
  for (;;) {
    // The next foreground neighbour counterclockwise from the way back.
    const int back = s;
    const unsigned around = ForegroundNeighbours(here, step);
    const int from = (back + 1) & 7;
    const unsigned turned = ((around | around << 8) >> from) & 0xFFu;
    s = (from + std::countr_zero(turned)) & 7;
    int8_t* next = here + delta[static_cast<size_t>(s)];
    if (static_cast<unsigned>(s - 1) < static_cast<unsigned>(back)) {
      *here = right_bound;  // the search passed the background pixel to the right
    } else if (*here == 1) {
      *here = mark;
    }
    ring.push_back(at);
    at.x += kStepX[static_cast<size_t>(s)];
    at.y += kStepY[static_cast<size_t>(s)];
    if (next == origin && here == second) break;
    here = next;
    s = (s + 4) & 7;
  }
}

// One border as found: its pixels, whether it is a hole's, and the border it belongs to
// (for a hole, the outer border of its region; -1 for the image frame).
struct Border {
  std::vector<cv::Point> ring;
  bool hole = false;
  int parent = -1;
};

// OpenCV's raster scan for border starts (Suzuki-Abe, two-level hierarchy): appends the
// borders in the order found. False when there are more borders than labels.
bool ScanBorders(FramedMask& image, cv::Point offset, std::vector<Border>& borders) {
  const int width = image.cols() - 1, height = image.rows() - 1;
  for (int y = 1; y < height; ++y) {
    int8_t* row = image.Row(y);
    int last_border = 0;  // x of the last marked pixel met in this row
    int prev = 0;
    for (int x = 1;; ++x) {
      x = NextChange(row, x, width, static_cast<int8_t>(prev));
      if (x >= width) break;
      const int p = row[x];
      const bool outer = prev == 0 && p == 1;
      const bool hole = !outer && p == 0 && prev >= 1;
      if (!outer && !hole) {
        prev = p;
        if ((prev & -2) != 0) last_border = x;
        continue;
      }
      if (hole && (prev & -2) != 0) last_border = x - 1;
      int parent = -1;
      if (hole && last_border > 0) {
        const int label = row[last_border] & 0x7f;
        if (label < kFirstLabel) return false;  // not a mark this scan made
        parent = label - kFirstLabel;
        if (borders[static_cast<size_t>(parent)].hole)
          parent = borders[static_cast<size_t>(parent)].parent;
      }
      const int label = kFirstLabel + static_cast<int>(borders.size());
      if (label > kLastLabel) return false;
      const int start = x - (hole ? 1 : 0);
      last_border = start;
      Border& border = borders.emplace_back();
      border.hole = hole;
      border.parent = parent;
      FollowBorder(row + start, image.cols(), cv::Point(start, y) + offset, hole, label,
                   border.ring);
      prev = row[x];
    }
  }
  return true;
}

// The borders in OpenCV's output order (each parent's children, and the top level, in the
// reverse order found, every border followed by its children) with its hierarchy.
void Emit(std::vector<Border>& borders, std::vector<std::vector<cv::Point>>& rings,
          std::vector<cv::Vec4i>& hierarchy) {
  const int n = static_cast<int>(borders.size());
  std::vector<std::vector<int>> children(static_cast<size_t>(n));
  std::vector<int> top;
  for (int i = n - 1; i >= 0; --i) {
    const int parent = borders[static_cast<size_t>(i)].parent;
    (parent < 0 ? top : children[static_cast<size_t>(parent)]).push_back(i);
  }
  std::vector<int> order, position(static_cast<size_t>(n));
  order.reserve(static_cast<size_t>(n));
  auto visit = [&](auto& self, int i) -> void {
    position[static_cast<size_t>(i)] = static_cast<int>(order.size());
    order.push_back(i);
    for (const int child : children[static_cast<size_t>(i)])
      self(self, child);
  };
  for (const int i : top)
    visit(visit, i);
  rings.resize(static_cast<size_t>(n));
  hierarchy.assign(static_cast<size_t>(n), cv::Vec4i(-1, -1, -1, -1));
  auto link = [&](const std::vector<int>& siblings, int parent) {
    for (size_t k = 0; k < siblings.size(); ++k) {
      cv::Vec4i& h = hierarchy[static_cast<size_t>(position[static_cast<size_t>(siblings[k])])];
      if (k + 1 < siblings.size()) h[0] = position[static_cast<size_t>(siblings[k + 1])];
      if (k > 0) h[1] = position[static_cast<size_t>(siblings[k - 1])];
      if (parent >= 0) h[3] = position[static_cast<size_t>(parent)];
    }
    if (parent >= 0 && !siblings.empty())
      hierarchy[static_cast<size_t>(position[static_cast<size_t>(parent)])][2] =
          position[static_cast<size_t>(siblings.front())];
  };
  link(top, -1);
  for (int i = 0; i < n; ++i)
    link(children[static_cast<size_t>(i)], i);
  for (int k = 0; k < n; ++k)
    rings[static_cast<size_t>(k)] =
        std::move(borders[static_cast<size_t>(order[static_cast<size_t>(k)])].ring);
}

}  // namespace

void TraceBorders(const cv::Mat& mask, const cv::Rect& box,
                  std::vector<std::vector<cv::Point>>& rings, std::vector<cv::Vec4i>& hierarchy) {
  SILNET_CHECK_MSG(mask.type() == CV_8UC1, "TraceBorders takes CV_8UC1 masks, got " << mask.type());
  SILNET_CHECK_MSG((box & cv::Rect(0, 0, mask.cols, mask.rows)) == box,
                   "box " << box << " outside the " << mask.cols << "x" << mask.rows << " mask");
  rings.clear();
  hierarchy.clear();
  if (box.area() == 0) return;
  FramedMask image(mask, box);
  std::vector<Border> borders;
  if (ScanBorders(image, box.tl() - cv::Point(1, 1), borders)) {
    Emit(borders, rings, hierarchy);
  } else {
    cv::findContours(mask(box), rings, hierarchy, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE, box.tl());
  }
}

}  // namespace silnet
