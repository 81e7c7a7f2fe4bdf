#pragma once
// Binary little-endian PLY files of oriented point clouds: one "vertex" element with float
// x, y, z, nx, ny, nz (metres, unit normals) and free-text comments. Simulated stills use it
// for the true surface (gt_surface.ply); MeshLab, CloudCompare and Open3D read it.

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace silnet {

// Points with normals (same length) and the header comments of a point-cloud PLY.
struct OrientedPointCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;
  std::vector<std::string> comments;  // one line each, without "comment "
};

// Writes `cloud` to `path`, returning the bytes written. Throws InputError if the file cannot
// be written and CheckError if points and normals differ in number or a comment has a newline.
std::size_t WritePointCloudPly(const std::filesystem::path& path, const OrientedPointCloud& cloud);

// Reads a file with exactly the layout WritePointCloudPly writes (any number of comments).
// Throws InputError naming the problem for another layout or a truncated file.
OrientedPointCloud ReadPointCloudPly(const std::filesystem::path& path);

}  // namespace silnet
