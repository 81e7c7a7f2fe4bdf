#pragma once
// Collected stills as the stereo job's input: the complete stills of the cameras of the
// calibration in use, each camera's model carried over to the still's resolution when the
// node took it larger or smaller than the calibration's images (CameraAtImageSize), and a
// summary file of the collection.

#include <filesystem>
#include <vector>

#include "aggregator/ingest/still_collector.h"
#include "aggregator/stereo/stereo_views.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The index of `camera`'s first frame exposed at or after reference time `t` seconds
// (conventions.h: frame k is exposed at (k + time_offset) / fps); 0 for times before frame 0.
uint64_t FirstFrameAtOrAfter(const CameraModel& camera, double t);

// The complete stills of `collection` whose camera `cameras` has, as views with their
// silhouettes (distortion kept as in the calibration). Stills without a camera, of another
// aspect ratio, with an empty silhouette or one its node flagged unreliable (background model
// warming up, segmentation failed, bad input) become warnings instead of views.
StereoViews StillViews(const StillCollection& collection, const std::vector<CameraModel>& cameras);

// Writes `<path>`: the still id, seconds, and per camera whether its still is complete (or
// why not), its frame, size, encoding, chunk counts and requests. Throws InputError if the
// file cannot be written.
void WriteStillSummary(const std::filesystem::path& path, const StillCollection& collection);

}  // namespace silnet::aggregator
