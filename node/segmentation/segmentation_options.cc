#include "node/segmentation/segmentation_options.h"

#include <fmt/format.h>

#include <functional>
#include <string_view>

#include "shared/util/check.h"
#include "shared/util/parse_number.h"

namespace silnet::node {
namespace {

bool ParseBool(const std::string& text, bool* out) {
  if (text == "true" || text == "1" || text == "on") {
    *out = true;
    return true;
  }
  if (text == "false" || text == "0" || text == "off") {
    *out = false;
    return true;
  }
  return false;
}

}  // namespace

SegmentationMethod ParseSegmentationMethod(const std::string& name) {
  if (name == "median") return SegmentationMethod::kMedian;
  if (name == "mog2") return SegmentationMethod::kMog2;
  if (name == "knn") return SegmentationMethod::kKnn;
  if (name == "mask") return SegmentationMethod::kMaskInput;
  throw InputError("unknown segmentation method '" + name + "' (use median, mog2, knn or mask)");
}

std::string ToString(SegmentationMethod method) {
  switch (method) {
    case SegmentationMethod::kMedian:
      return "median";
    case SegmentationMethod::kMog2:
      return "mog2";
    case SegmentationMethod::kKnn:
      return "knn";
    case SegmentationMethod::kMaskInput:
      return "mask";
  }
  return "unknown";
}

std::string SegmentationOptions::Validate() const {
  if (median_samples < 3 || median_samples > 63) return "median_samples must be 3..63";
  if (median_stride < 1 || median_stride > 1000) return "median_stride must be 1..1000";
  if (!(threshold_sigmas > 0.0)) return "threshold_sigmas must be positive";
  if (min_difference < 0.0 || min_difference > 255.0) return "min_difference must be 0..255";
  if (learning_rate < 0.0 || learning_rate > 1.0) return "learning_rate must be 0..1";
  if (!(shadow_min_ratio > 0.0 && shadow_min_ratio < shadow_max_ratio && shadow_max_ratio <= 1.0)) {
    return "shadow ratios must satisfy 0 < shadow_min_ratio < shadow_max_ratio <= 1";
  }
  if (shadow_chroma < 0.0 || shadow_texture < 0.0) {
    return "shadow_chroma and shadow_texture must be non-negative";
  }
  if (history < 1) return "history must be positive";
  if (!(opencv_threshold > 0.0)) return "opencv_threshold must be positive";
  if (open_radius < 0 || open_radius > 10 || close_radius < 0 || close_radius > 10) {
    return "open_radius and close_radius must be 0..10";
  }
  if (min_blob_area < 0 || max_hole_area < 0) return "blob and hole areas must be non-negative";
  if (graph_cut_band < 1 || graph_cut_band > 32) return "graph_cut_band must be 1..32";
  if (mask_threshold < 0 || mask_threshold > 254) return "mask_threshold must be 0..254";
  return {};
}

bool SegmentationOptions::Set(const std::string& name, const std::string& value,
                              std::string* error) {
  auto number = [&](double* field) { return ParseWholeNumber(value, field); };
  auto integer = [&](int* field) { return ParseWholeNumber(value, field); };
  auto flag = [&](bool* field) { return ParseBool(value, field); };
  const std::map<std::string, std::function<bool()>> setters = {
      {"method",
       [&] {
         try {
           method = ParseSegmentationMethod(value);
           return true;
         } catch (const InputError&) {
           return false;
         }
       }},
      {"median_samples", [&] { return integer(&median_samples); }},
      {"median_stride", [&] { return integer(&median_stride); }},
      {"threshold_sigmas", [&] { return number(&threshold_sigmas); }},
      {"min_difference", [&] { return number(&min_difference); }},
      {"learning_rate", [&] { return number(&learning_rate); }},
      {"suppress_shadows", [&] { return flag(&suppress_shadows); }},
      {"shadow_min_ratio", [&] { return number(&shadow_min_ratio); }},
      {"shadow_max_ratio", [&] { return number(&shadow_max_ratio); }},
      {"shadow_chroma", [&] { return number(&shadow_chroma); }},
      {"shadow_texture", [&] { return number(&shadow_texture); }},
      {"history", [&] { return integer(&history); }},
      {"opencv_threshold", [&] { return number(&opencv_threshold); }},
      {"open_radius", [&] { return integer(&open_radius); }},
      {"close_radius", [&] { return integer(&close_radius); }},
      {"min_blob_area", [&] { return integer(&min_blob_area); }},
      {"max_hole_area", [&] { return integer(&max_hole_area); }},
      {"graph_cut", [&] { return flag(&graph_cut); }},
      {"graph_cut_band", [&] { return integer(&graph_cut_band); }},
      {"mask_threshold", [&] { return integer(&mask_threshold); }},
  };
  const auto it = setters.find(name);
  if (it == setters.end()) {
    if (error != nullptr) *error = "unknown segmentation setting '" + name + "'";
    return false;
  }
  if (!it->second()) {
    if (error != nullptr)
      *error = "cannot parse '" + value + "' for segmentation setting '" + name + "'";
    return false;
  }
  return true;
}

std::map<std::string, std::string> SegmentationOptions::ToMap() const {
  return {
      {"method", ToString(method)},
      {"median_samples", std::to_string(median_samples)},
      {"median_stride", std::to_string(median_stride)},
      {"threshold_sigmas", fmt::format("{}", threshold_sigmas)},
      {"min_difference", fmt::format("{}", min_difference)},
      {"learning_rate", fmt::format("{}", learning_rate)},
      {"suppress_shadows", suppress_shadows ? "true" : "false"},
      {"shadow_min_ratio", fmt::format("{}", shadow_min_ratio)},
      {"shadow_max_ratio", fmt::format("{}", shadow_max_ratio)},
      {"shadow_chroma", fmt::format("{}", shadow_chroma)},
      {"shadow_texture", fmt::format("{}", shadow_texture)},
      {"history", std::to_string(history)},
      {"opencv_threshold", fmt::format("{}", opencv_threshold)},
      {"open_radius", std::to_string(open_radius)},
      {"close_radius", std::to_string(close_radius)},
      {"min_blob_area", std::to_string(min_blob_area)},
      {"max_hole_area", std::to_string(max_hole_area)},
      {"graph_cut", graph_cut ? "true" : "false"},
      {"graph_cut_band", std::to_string(graph_cut_band)},
      {"mask_threshold", std::to_string(mask_threshold)},
  };
}

}  // namespace silnet::node
