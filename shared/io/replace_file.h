#pragma once
// Writing a file that readers poll (a status file, a report page a browser reloads): written
// beside its path and renamed over it, so a reader sees the old file or the whole new one,
// never half of it.

#include <filesystem>
#include <functional>
#include <string_view>

namespace silnet {

// Replaces `path` with what `write` puts into the file it is given (`path` + ".partial"),
// renamed over `path` once `write` returns. If `write` throws, the partial file is removed,
// `path` is left as it was and the exception goes on; if the rename fails, InputError.
void ReplaceFileThrough(const std::filesystem::path& path,
                        const std::function<void(const std::filesystem::path& partial)>& write);

// Replaces `path` with `contents` that way. Throws InputError (and leaves `path` as it was)
// if the file cannot be written.
void ReplaceFile(const std::filesystem::path& path, std::string_view contents);

}  // namespace silnet
