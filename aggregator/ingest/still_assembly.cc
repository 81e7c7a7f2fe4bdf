#include "aggregator/ingest/still_assembly.h"

#include <fmt/format.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "node/segmentation/weak_silhouette.h"
#include "shared/dds/topics.h"
#include "shared/util/crc32.h"

namespace silnet::aggregator {
namespace {

// Chunks a still may have at most (1 GiB in 16 KiB chunks).
constexpr uint32_t kMaxChunks = 65536;

}  // namespace

ChunkVerdict StillPartAssembly::Accept(const silnet_wire_Still& sample) {
  if (sample.chunk_count == 0 || sample.chunk_count > kMaxChunks ||
      sample.chunk_index >= sample.chunk_count || sample.image_bytes == 0 ||
      sample.image_width == 0 || sample.image_height == 0 ||
      sample.data._length > sample.image_bytes) {
    return ChunkVerdict::kMalformed;
  }
  const std::string sample_encoding = dds::ReadBoundedString(sample.encoding);
  if (sample_encoding != "png" && sample_encoding != "jpeg") return ChunkVerdict::kMalformed;
  if (chunks_.empty()) {
    chunk_count_ = sample.chunk_count;
    image_bytes_ = sample.image_bytes;
    image_crc_ = sample.image_crc32;
    width = sample.image_width;
    height = sample.image_height;
    frame_index = sample.frame_index;
    frame_flags = sample.frame_flags;
    capture_time_ns = sample.capture_time_ns;
    encoding = sample_encoding;
    chunks_.resize(chunk_count_);
  } else if (sample.chunk_count != chunk_count_ || sample.image_bytes != image_bytes_ ||
             sample.image_crc32 != image_crc_ || sample.image_width != width ||
             sample.image_height != height || sample.frame_index != frame_index ||
             sample.frame_flags != frame_flags || sample_encoding != encoding) {
    return ChunkVerdict::kMalformed;
  }
  if (Crc32(0, sample.data._buffer, sample.data._length) != sample.chunk_crc32)
    return ChunkVerdict::kCorrupt;
  std::optional<std::vector<uint8_t>>& slot = chunks_[sample.chunk_index];
  if (slot) return ChunkVerdict::kDuplicate;
  slot.emplace(sample.data._buffer, sample.data._buffer + sample.data._length);
  if (++held_ < chunks_.size()) return ChunkVerdict::kAccepted;
  // The last chunk: the whole image must add up to what the node announced. Every chunk
  // intact but the image not: the chunks do not belong together, all are fetched again.
  uint64_t bytes = 0;
  uint32_t crc = 0;
  for (const auto& chunk : chunks_) {
    bytes += chunk->size();
    crc = Crc32(crc, chunk->data(), chunk->size());
  }
  complete_ = bytes == image_bytes_ && crc == image_crc_;
  if (!complete_) {
    Reset();
    return ChunkVerdict::kMalformed;
  }
  return ChunkVerdict::kAccepted;
}

std::vector<std::pair<uint32_t, uint32_t>> StillPartAssembly::Missing() const {
  std::vector<std::pair<uint32_t, uint32_t>> ranges;
  for (uint32_t i = 0; i < chunks_.size(); ++i) {
    if (chunks_[i]) continue;
    if (!ranges.empty() && ranges.back().second + 1 == i)
      ranges.back().second = i;
    else
      ranges.emplace_back(i, i);
  }
  return ranges;
}

std::vector<uint8_t> StillPartAssembly::Bytes() const {
  std::vector<uint8_t> bytes;
  bytes.reserve(image_bytes_);
  for (const auto& chunk : chunks_)
    if (chunk) bytes.insert(bytes.end(), chunk->begin(), chunk->end());
  return bytes;
}

void StillPartAssembly::Reset() {
  for (auto& chunk : chunks_)
    chunk.reset();
  held_ = 0;
  complete_ = false;
}

ChunkVerdict StillAssembly::Accept(const silnet_wire_Still& sample) {
  ChunkVerdict verdict = ChunkVerdict::kMalformed;
  if (sample.still_id == still_id_ &&
      (sample.part == silnet_wire_STILL_PHOTO || sample.part == silnet_wire_STILL_SILHOUETTE)) {
    verdict = part(sample.part).Accept(sample);
  }
  switch (verdict) {
    case ChunkVerdict::kAccepted:
      ++counts_.accepted;
      break;
    case ChunkVerdict::kDuplicate:
      ++counts_.duplicates;
      break;
    case ChunkVerdict::kCorrupt:
      ++counts_.corrupt;
      break;
    case ChunkVerdict::kMalformed:
      ++counts_.malformed;
      break;
  }
  return verdict;
}

std::string StillAssembly::Decode(cv::Mat* photo, cv::Mat* silhouette) {
  if (!Complete()) return "incomplete";
  if (photo_.frame_index != silhouette_.frame_index) {
    silhouette_.Reset();
    return fmt::format("photo of frame {} but silhouette of frame {}", photo_.frame_index,
                       silhouette_.frame_index);
  }
  *photo = cv::imdecode(photo_.Bytes(), cv::IMREAD_COLOR);
  if (photo->empty() || photo->cols != photo_.width || photo->rows != photo_.height) {
    const std::string why = photo->empty()
                                ? "the photo does not decode"
                                : fmt::format("the photo is {}x{}, announced {}x{}", photo->cols,
                                              photo->rows, photo_.width, photo_.height);
    photo_.Reset();
    return why;
  }
  cv::Mat grey = cv::imdecode(silhouette_.Bytes(), cv::IMREAD_GRAYSCALE);
  if (grey.empty() || grey.size() != photo->size()) {
    silhouette_.Reset();
    return grey.empty() ? "the silhouette does not decode"
                        : "the silhouette's size differs from the photo's";
  }
  cv::compare(grey, 0, *silhouette, cv::CMP_NE);
  // Weak evidence beside the silhouette keeps its mark for the multi-view check.
  silhouette->setTo(node::kWeakSilhouette, grey == node::kWeakSilhouette);
  return "";
}

}  // namespace silnet::aggregator
