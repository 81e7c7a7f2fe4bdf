#pragma once
// COLMAP text export of a calibrated network (DESIGN.md "Files"; COLMAP's "Output Format"
// documentation): cameras.txt (PINHOLE; OPENCV with k1, k2, p1, p2 when the camera has
// distortion; FULL_OPENCV when k3 is not zero), images.txt (one image per placed camera,
// named <camera id>.png (white space in the id replaced by '_'), pose as COLMAP's world-to-camera
// quaternion (Hamilton, w first, w >= 0) and translation, with its frontier-point observations as
// POINTS2D) and points3D.txt (the frontier points with their mean reprojection error, grey colour
// and two-view tracks).
//
// Ids: a placed camera's CAMERA_ID and IMAGE_ID are both its index in
// NetworkCalibration::cameras plus one (so they are stable but not contiguous when cameras
// are unplaced); POINT3D_IDs are 1, 2, ... over the exported points. Pixels: COLMAP puts
// the centre of the top-left pixel at (0.5, 0.5) and silnet at (0, 0) (conventions.h), so
// principal points and observed pixels are shifted by +0.5. COLMAP has no skew; it is
// dropped (silnet's Euclidean bundle adjustment fixes it at zero).

#include <filesystem>

#include "aggregator/calibration/calibration_result.h"

namespace silnet::aggregator {

// Writes the three files into `dir` (created if needed); only placed cameras and inlier
// points whose two views are placed cameras are exported. Throws InputError naming the path
// if the folder or a file cannot be written.
void WriteColmapText(const std::filesystem::path& dir, const NetworkCalibration& calibration);

}  // namespace silnet::aggregator
