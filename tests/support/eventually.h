#pragma once
// Waiting for a condition instead of for a time, so tests hold on a busy machine.

#include <chrono>
#include <functional>

namespace silnet::testing {

// Checks `done` every `interval` until it holds or `timeout` has passed; true once it held
// (it is checked once more at the deadline).
bool Eventually(const std::function<bool()>& done, std::chrono::milliseconds timeout,
                std::chrono::milliseconds interval = std::chrono::milliseconds(200));

}  // namespace silnet::testing
