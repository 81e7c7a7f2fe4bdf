#include "shared/io/replace_file.h"

#include <fmt/format.h>

#include <fstream>
#include <system_error>

#include "shared/util/check.h"

namespace silnet {

void ReplaceFileThrough(const std::filesystem::path& path,
                        const std::function<void(const std::filesystem::path& partial)>& write) {
  std::filesystem::path partial = path;
  partial += ".partial";
  std::error_code error;
  try {
    write(partial);
  } catch (...) {
    std::filesystem::remove(partial, error);
    throw;
  }
  std::filesystem::rename(partial, path, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw InputError(fmt::format("cannot write {}: {}", path.string(), error.message()));
  }
}

void ReplaceFile(const std::filesystem::path& path, std::string_view contents) {
  ReplaceFileThrough(path, [&](const std::filesystem::path& partial) {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) throw InputError(fmt::format("cannot write {}", partial.string()));
  });
}

}  // namespace silnet
