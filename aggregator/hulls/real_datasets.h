#pragma once
// Loaders for public single-frame silhouette datasets (shared data folder, see its
// README.md), turning each into silnet cameras (shared/geometry/conventions.h) and masks, so
// visual hulls can be checked on real captures.
//
// * INRIA "dancer" (dancer_par.txt + dancer000N.pbm): one 3x4 projection matrix per view,
//   decomposed into K [R | t] (R a rotation, positive focal lengths); binary PBM (P4) masks
//   whose foreground is the 0 bit.
// * Tsinghua "WD2" 20-camera capture (calibParamsI.txt + silhouettes/*.png): K (with skew),
//   two radial coefficients and [R | t] world -> camera; RGB masks thresholded at > 125.
// * EPVH's "alien" (alien-camera.txt, alien-contour.txt): 24 projection matrices and
//   sub-pixel contours, the data of the exact-hull peer.
// Both files' pixel coordinates are taken as silnet's (integer = pixel centre); the
// half-pixel ambiguity is far below a voxel.

#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Cameras and their CV_8UC1 masks (255 silhouette, 0 background) of one instant.
struct RealCapture {
  std::vector<CameraModel> cameras;  // fps 30 and time offset 0 (one instant)
  std::vector<cv::Mat> masks;        // masks[c] is cameras[c]'s silhouette, its size
};

// Reads a binary PBM (P4) file; CV_8UC1 with 255 where the bit is `foreground_bit`.
// Throws InputError for other or truncated files.
cv::Mat ReadPbm(const std::filesystem::path& path, int foreground_bit);

// Loads the dancer folder. Throws InputError naming the file for missing or malformed input.
RealCapture LoadInriaDancer(const std::filesystem::path& folder);

// Loads the WD2 folder. The file's radial coefficients become k1, k2 iff `use_distortion`
// (the dataset's own code ignores them). Throws InputError for missing or malformed input.
RealCapture LoadTsinghuaWd2(const std::filesystem::path& folder, bool use_distortion);

// Loads the first `views` cameras (all when 0) of EPVH's "alien" set (alien-camera.txt: 3x4
// projection matrices, blank-line separated, decomposed into K [R | t] with K's small skew
// kept; alien-contour.txt: one sub-pixel outer contour per camera, "index count" then the x y
// list), images 1900x1600. Masks are the contours filled at 1/16 px (pixels whose centres lie
// inside). Throws InputError naming the file for missing or malformed input, or `views` > 24.
RealCapture LoadEpvhAlien(const std::filesystem::path& folder, int views = 0);

// Reads the cameras of a Utrecht INFOMCV capture (cam1..camN/config.xml: OpenCV FileStorage
// with K, five distortion coefficients, a Rodrigues rotation and a translation in mm,
// x_cam = R X + t; either the `camera_matrix`/`distortion_coefficients`/`rotation_vectors`/
// `translation_vectors` or the `CameraMatrix`/`DistortionCoeffs`/`Rotation`/`Translation`
// names), with the image size of the first .avi file in each camera folder and frame rate
// `fps`. Cameras are named by their folders. Throws InputError for missing or malformed input
// (values that are not finite, a camera matrix without positive focal lengths or 0 0 1 below).
std::vector<CameraModel> LoadUtrechtCameras(const std::filesystem::path& folder, double fps);

// The mask with only its largest 8-connected silhouette component kept (CV_8UC1, 0/255).
cv::Mat KeepLargestComponent(const cv::Mat& mask);

}  // namespace silnet::aggregator
