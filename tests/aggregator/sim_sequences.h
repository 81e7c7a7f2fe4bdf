#pragma once
// Simulated silhouette sequences for pairwise tests: exact masks rendered by the simulator
// and passed through the real node encoder (mask input -> hull -> HullFrame encoding), then
// decoded as the aggregator does.

#include <functional>
#include <memory>
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
  std::vector<CameraModel> cameras;         // as at frame 0
  std::vector<CameraModel> cameras_at_end;  // after any camera moves
  std::unique_ptr<sim::Scene> scene;
  std::vector<SilhouetteSequence> sequences;
};

// Optional damage to the masks before encoding (camera index, frame, mask, rng).
using MaskDamage = std::function<void(size_t, int, cv::Mat*, std::mt19937_64*)>;

// Renders `frames` exact masks of every camera and encodes them with the node's pipeline.
SimCapture MakeSimCapture(const sim::CameraNetworkOptions& network, const sim::SceneOptions& scene,
                          int frames, const MaskDamage& damage = {});

// Exact masks as MakeSimCapture renders them, with camera `move.camera` moved from frame
// `move.frame` on.
SimCapture MakeSimCaptureWithMove(const sim::CameraNetworkOptions& network,
                                  const sim::SceneOptions& scene, int frames,
                                  const sim::CameraMove& move);

// The default 8-camera ring (seed 1) of `frames` exact masks, camera `camera` knocked at
// `move_frame`: turned 2 degrees about a slightly tilted vertical axis and shifted 6 cm.
SimCapture MakeRingWithKnockedCamera(size_t camera, int move_frame, int frames);

// The frames [first, first + count) of each sequence.
std::vector<SilhouetteSequence> SliceSequences(const std::vector<SilhouetteSequence>& sequences,
                                               uint64_t first, uint64_t count);

// Renders `frames` colour frames of every camera (default sensor noise, shadows, lighting
// changes) and runs the node's whole pipeline on them: median-model segmentation, clean-up,
// hull, encoding. The model's warm-up frames are flagged FRAME_WARMUP, as on the wire.
SimCapture MakeSegmentedSimCapture(const sim::CameraNetworkOptions& network,
                                   const sim::SceneOptions& scene, int frames);

// The cameras as a calibration receives them: id, image size and frame rate only.
std::vector<CameraModel> UncalibratedCopies(const std::vector<CameraModel>& truth);

}  // namespace silnet::aggregator::testing
