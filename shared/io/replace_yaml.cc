#include "shared/io/replace_yaml.h"

#include <fmt/format.h>

#include <opencv2/core.hpp>
#include <system_error>

#include "shared/util/check.h"

namespace silnet {

void ReplaceYaml(const std::filesystem::path& path,
                 const std::function<void(cv::FileStorage&)>& write) {
  std::filesystem::path partial = path;
  partial += ".partial";
  std::error_code error;
  try {
    cv::FileStorage fs(partial.string(), cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) throw InputError(fmt::format("cannot write {}", partial.string()));
    write(fs);
  } catch (const cv::Exception& e) {
    std::filesystem::remove(partial, error);
    throw InputError(fmt::format("cannot write {}: {}", partial.string(), e.what()));
  } catch (...) {
    std::filesystem::remove(partial, error);
    throw;
  }
  std::filesystem::rename(partial, path, error);
  if (error) throw InputError(fmt::format("cannot write {}: {}", path.string(), error.message()));
}

}  // namespace silnet
