#pragma once
// A temporary folder removed (with its contents) when the object goes.

#include <filesystem>
#include <string>

namespace silnet::testing {

// Creates a fresh folder under the system temporary directory.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "silnet-test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace silnet::testing
