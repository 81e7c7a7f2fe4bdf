#pragma once
// The order in which an incremental reconstruction adds cameras (thesis 3.2.4): next is the
// camera whose second-strongest link into the reconstruction is strongest (links ranked by
// their inlier spread score), through its two strongest links that are not degenerate.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/calibration/view_graph.h"

namespace silnet::aggregator {

// A camera ready to be added through two cameras already placed.
struct Addition {
  size_t camera = 0;
  size_t first = 0;   // the placed camera with the stronger link
  size_t second = 0;  // the other
  double score = -1.0;
};

// True if camera k can be added through placed cameras p and q (e.g. centres not collinear).
using AdditionCheck = std::function<bool(size_t k, size_t p, size_t q)>;

// The next camera to add, or nullopt if no camera outside `placed` (and not `given_up`) has
// two acceptable links into it.
std::optional<Addition> NextAddition(const ViewGraph& graph, const std::vector<bool>& placed,
                                     const std::vector<bool>& given_up,
                                     const AdditionCheck& acceptable);

// Why camera k was not added, for the user: no links, too few into the placed cameras, or
// degenerate ones.
std::string ReasonNotPlaced(const ViewGraph& graph, const std::vector<bool>& placed, size_t k);

}  // namespace silnet::aggregator
