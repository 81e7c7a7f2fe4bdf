#include "shared/io/replace_yaml.h"

#include <fmt/format.h>

#include <opencv2/core.hpp>

#include "shared/io/replace_file.h"
#include "shared/util/check.h"

namespace silnet {

void ReplaceYaml(const std::filesystem::path& path,
                 const std::function<void(cv::FileStorage&)>& write) {
  ReplaceFileThrough(path, [&](const std::filesystem::path& partial) {
    try {
      cv::FileStorage fs(partial.string(), cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
      if (!fs.isOpened()) throw InputError(fmt::format("cannot write {}", partial.string()));
      write(fs);
      fs.release();
    } catch (const cv::Exception& e) {
      throw InputError(fmt::format("cannot write {}: {}", partial.string(), e.what()));
    }
  });
}

}  // namespace silnet
