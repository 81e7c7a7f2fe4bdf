#pragma once
// A minimal work-sharing loop over an index range on a few threads.

#include <cstddef>
#include <functional>

#include "shared/util/progress.h"

namespace silnet {

// Calls fn(i) for every i in [0, n) on `threads` threads (0 = hardware concurrency).
// Items are handed out one at a time, so uneven items balance. The first exception thrown
// by fn stops the hand-out and is rethrown in the caller once all threads have returned.
// The results must not depend on which thread ran an item.
void ParallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& fn);
// As above, but no item is handed out once cancel->cancelled() (`cancel` may be null): the
// caller must check it afterwards and not use the results, some items having not run.
void ParallelFor(std::size_t n, int threads, const Progress* cancel,
                 const std::function<void(std::size_t)>& fn);

// Number of threads ParallelFor uses for `threads` (resolves 0 and caps at n).
int ResolveThreadCount(int threads, std::size_t n);

}  // namespace silnet
