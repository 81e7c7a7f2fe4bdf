#pragma once
// Guards for YAML text before OpenCV's FileStorage parses it. Its parser (OpenCV 4.6)
// recurses once per nesting level, so a few hundred kilobytes of brackets or dashes overflow
// the stack and kill the process; and it loops forever on some malformed files (24 bytes
// were enough: a map indented by three or more spaces, then "-  -" and a blank line).

#include <chrono>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "shared/util/check.h"

namespace silnet {

// Deepest nesting accepted: flow collections ('[' and '{', counted wherever they appear, in
// quoted text and comments too) and block indentation (the spaces, tabs and sequence dashes
// that start a line). Far beyond any calibration or job file silnet reads or writes.
inline constexpr int kMaxYamlFlowDepth = 256;
inline constexpr int kMaxYamlIndentColumns = 1024;

// Empty if `text` nests within the limits above, else a reason for the user ("nests '[' and
// '{' more than 256 deep (line 3)").
std::string YamlNestingProblem(std::string_view text);

// How long OpenCV's parser may take on a file before it counts as looping forever: files of
// hundreds of cameras parse in milliseconds.
inline constexpr std::chrono::milliseconds kYamlParseLimit{5000};

// Empty if OpenCV's parser finishes on `text` (with or without an error) within `limit`,
// else why not: it crashed, or it was still running at the limit. It is tried in a child
// process, killed at the limit, so a parser that crashes or loops forever costs this process
// nothing. Empty too if no child can be started (the caller's parse is then unguarded).
// FileStorage reads XML too, with the same guard; `format` names the parser in the reason.
std::string YamlParserProblem(const std::string& text, std::chrono::milliseconds limit,
                              std::string_view format = "YAML");

// read(), with what OpenCV's parser and nodes throw (their own exceptions, and the standard
// library's for lengths or allocations a malformed file asks for) turned into InputError
// "`path`: `what` (reason)"; InputError passes unchanged.
template <class Read>
auto ReadYamlGuarded(const std::filesystem::path& path, const char* what, Read read) {
  try {
    return read();
  } catch (const InputError&) {
    throw;
  } catch (const cv::Exception& e) {
    throw InputError(path.string() + ": " + what + " (" + e.err + ")");
  } catch (const std::exception& e) {
    throw InputError(path.string() + ": " + what + " (" + e.what() + ")");
  }
}

// Opens `path` as an OpenCV FileStorage for reading (YAML, or XML: FileStorage tells them by
// their first line) behind the guards above. Throws InputError naming the path for a missing
// or unreadable file, "`path`: `refused``reason`" for one nested deeper than the parser
// survives or on which it crashes or is still running after `parse_limit`, and for one the
// parser refuses. `format` names the parser in the reasons.
cv::FileStorage OpenFileStorageGuarded(const std::filesystem::path& path, std::string_view format,
                                       std::string_view refused = "",
                                       std::chrono::milliseconds parse_limit = kYamlParseLimit);

}  // namespace silnet
