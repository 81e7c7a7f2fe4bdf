#pragma once
// Writing a YAML file that readers poll: written beside its path and renamed over it, so a
// reader sees the old file or the whole new one, never half of it.

#include <filesystem>
#include <functional>
#include <opencv2/core/persistence.hpp>

namespace silnet {

// Writes `path` with `write` (into a cv::FileStorage open for writing YAML) through a
// ".partial" file renamed over it; if it cannot be written (InputError) or `write` throws,
// the partial file is removed and `path` is left as it was.
void ReplaceYaml(const std::filesystem::path& path,
                 const std::function<void(cv::FileStorage&)>& write);

}  // namespace silnet
