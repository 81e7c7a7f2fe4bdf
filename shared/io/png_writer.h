#pragma once
// Fast PNG encoding through libpng with settings chosen for speed (measured in
// docs/PERFORMANCE.md): one fixed filter and zlib level 1. Colour images use the Sub
// filter with Huffman-only coding, binary masks no filter with run-length-friendly
// deflate. The files are ordinary PNGs any reader (cv::imread) decodes.

#include <cstdint>
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace silnet {

// Encodes an 8-bit greyscale (CV_8UC1) or BGR (CV_8UC3) image. Throws CheckError for any
// other type and std::runtime_error if libpng fails.
std::vector<uint8_t> EncodePngFast(const cv::Mat& image);

// Encodes and writes `image` to `path`, returning the bytes written; throws InputError if
// the file cannot be written.
std::size_t WritePngFast(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace silnet
