#include "shared/io/png_writer.h"

#include <png.h>
#include <zlib.h>

#include <cstdio>
#include <stdexcept>

#include "shared/util/check.h"

namespace silnet {
namespace {

void AppendToVector(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + length);
}

void NoFlush(png_structp) {}

// Runs libpng; returns false if it reported an error. Only trivially destructible locals
// live across setjmp, so libpng's longjmp skips no destructor.
bool EncodeWithLibpng(const cv::Mat& image, std::vector<uint8_t>* out) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  const bool colour = image.channels() == 3;
  png_set_write_fn(png, out, AppendToVector, NoFlush);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), 8,
               colour ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, colour ? PNG_FILTER_SUB : PNG_FILTER_NONE);
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, colour ? Z_HUFFMAN_ONLY : Z_DEFAULT_STRATEGY);
  png_write_info(png, info);
  if (colour) png_set_bgr(png);
  for (int row = 0; row < image.rows; ++row) {
    png_write_row(png, const_cast<png_bytep>(image.ptr<png_byte>(row)));
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

std::vector<uint8_t> EncodePngFast(const cv::Mat& image) {
  SILNET_CHECK_MSG(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
                   "EncodePngFast takes CV_8UC1 or CV_8UC3, got type " << image.type());
  std::vector<uint8_t> out;
  out.reserve(image.total() * image.elemSize() / 2 + 1024);
  if (!EncodeWithLibpng(image, &out)) throw std::runtime_error("libpng failed to encode an image");
  return out;
}

std::size_t WritePngFast(const std::filesystem::path& path, const cv::Mat& image) {
  const std::vector<uint8_t> bytes = EncodePngFast(image);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) throw InputError(path.string() + ": cannot open for writing");
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), file);
  const bool closed = std::fclose(file) == 0;
  if (written != bytes.size() || !closed) throw InputError(path.string() + ": write failed");
  return written;
}

}  // namespace silnet
