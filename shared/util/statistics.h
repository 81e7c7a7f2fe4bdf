#pragma once
// Small statistics over samples.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace silnet {

// The upper median: the value at index n / 2 once sorted (for an even count, the larger of
// the two middle values); 0 for no values. Linear time.
inline double UpperMedian(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace silnet
