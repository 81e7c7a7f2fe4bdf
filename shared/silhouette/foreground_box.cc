#include "shared/silhouette/foreground_box.h"

#include <cstdint>
#include <cstring>

#include "shared/util/check.h"

namespace silnet {
namespace {

// Eight bytes of a row, in memory order.
uint64_t Word(const uint8_t* p) {
  uint64_t word;
  std::memcpy(&word, p, sizeof word);
  return word;
}

// The first non-zero byte of row[0, end), or end.
int FirstForeground(const uint8_t* row, int end) {
  int x = 0;
  while (x + 32 <= end &&
         (Word(row + x) | Word(row + x + 8) | Word(row + x + 16) | Word(row + x + 24)) == 0)
    x += 32;
  while (x + 8 <= end && Word(row + x) == 0)
    x += 8;
  while (x < end && row[x] == 0)
    ++x;
  return x;
}

// The last non-zero byte of row(begin, width), or begin.
int LastForeground(const uint8_t* row, int begin, int width) {
  int x = width;  // one past the candidate
  while (x - 32 > begin &&
         (Word(row + x - 32) | Word(row + x - 24) | Word(row + x - 16) | Word(row + x - 8)) == 0)
    x -= 32;
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
