#pragma once
// Simulated silhouette sequences for pairwise tests: exact masks rendered by the simulator
// and passed through the real node encoder (mask input -> hull -> HullFrame encoding), then
// decoded as the aggregator does.

#include <functional>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "aggregator/pairwise/silhouette_sequence.h"
#include "shared/geometry/camera_model.h"
#include "sim/camera_network.h"
#include "sim/scene/scene.h"

namespace silnet::aggregator::testing {

// Ground truth and sequences of one simulated capture.
struct SimCapture {
  std::vector<CameraModel> cameras;
  std::unique_ptr<sim::Scene> scene;
  std::vector<SilhouetteSequence> sequences;
};

// Optional damage to the masks before encoding (camera index, frame, mask, rng).
using MaskDamage = std::function<void(size_t, int, cv::Mat*, std::mt19937_64*)>;

// Renders `frames` frames of every camera and encodes them with the node's pipeline.
SimCapture MakeSimCapture(const sim::CameraNetworkOptions& network, const sim::SceneOptions& scene,
                          int frames, const MaskDamage& damage = {});

}  // namespace silnet::aggregator::testing
