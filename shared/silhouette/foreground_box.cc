#include "shared/silhouette/foreground_box.h"

#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "shared/util/check.h"

namespace silnet {
namespace {

// Eight bytes of a row, in memory order.
uint64_t Word(const uint8_t* p) {
  uint64_t word;
  std::memcpy(&word, p, sizeof word);
  return word;
}

// True if the 64 bytes from p are all zero.
bool Zero64(const uint8_t* p) {
#if defined(__SSE2__)
  const auto load = [p](int offset) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + offset));
  };
  const __m128i any =
      _mm_or_si128(_mm_or_si128(load(0), load(16)), _mm_or_si128(load(32), load(48)));
  return _mm_movemask_epi8(_mm_cmpeq_epi8(any, _mm_setzero_si128())) == 0xFFFF;
#else
  return ((Word(p) | Word(p + 8)) | (Word(p + 16) | Word(p + 24)) |
          ((Word(p + 32) | Word(p + 40)) | (Word(p + 48) | Word(p + 56)))) == 0;
#endif
}

// The first non-zero byte of row[0, end), or end.
int FirstForeground(const uint8_t* row, int end) {
  int x = 0;
  while (x + 64 <= end && Zero64(row + x))
    x += 64;
  while (x + 8 <= end && Word(row + x) == 0)
    x += 8;
  while (x < end && row[x] == 0)
    ++x;
  return x;
}

// The last non-zero byte of row(begin, width), or begin.
int LastForeground(const uint8_t* row, int begin, int width) {
  int x = width;  // one past the candidate
  while (x - 64 > begin && Zero64(row + x - 64))
    x -= 64;
  while (x - 8 > begin && Word(row + x - 8) == 0)
    x -= 8;
  while (x - 1 > begin && row[x - 1] == 0)
    --x;
  return x - 1;
}

}  // namespace

cv::Rect ForegroundBox(const cv::Mat& mask) {
  SILNET_CHECK_MSG(mask.type() == CV_8UC1,
                   "ForegroundBox takes CV_8UC1 masks, got " << mask.type());
  const int width = mask.cols;
  const auto empty = [&](int y) { return FirstForeground(mask.ptr<uint8_t>(y), width) == width; };
  int top = 0;
  while (top < mask.rows && empty(top))
    ++top;
  if (top == mask.rows) return {};
  int bottom = mask.rows - 1;
  while (empty(bottom))
    --bottom;
  // Each row's margins are scanned only up to the box's current sides.
  int left = width, right = -1;
  for (int y = top; y <= bottom; ++y) {
    const uint8_t* row = mask.ptr<uint8_t>(y);
    left = FirstForeground(row, left);
    right = LastForeground(row, right, width);
  }
  return {left, top, right - left + 1, bottom - top + 1};
}

}  // namespace silnet
