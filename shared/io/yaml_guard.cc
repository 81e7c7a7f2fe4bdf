#include "shared/io/yaml_guard.h"

#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <sstream>
#include <thread>

namespace silnet {

std::string YamlNestingProblem(std::string_view text) {
  int depth = 0, line = 1, column = 0;
  bool indent = true;  // still in the characters that start the line
  for (const char c : text) {
    if (c == '\n') {
      ++line;
      column = 0;
      indent = true;
      continue;
    }
    if (indent && (c == ' ' || c == '\t' || c == '-')) {
      if (++column > kMaxYamlIndentColumns) {
        return fmt::format("line {} is indented or nested in sequences more than {} columns deep",
                           line, kMaxYamlIndentColumns);
      }
    } else {
      indent = false;
    }
    if (c == '[' || c == '{') {
      if (++depth > kMaxYamlFlowDepth) {
        return fmt::format("nests '[' and '{{' more than {} deep (line {})", kMaxYamlFlowDepth,
                           line);
      }
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return {};
}

std::string YamlParserProblem(const std::string& text, std::chrono::milliseconds limit,
                              std::string_view format) {
  const pid_t child = ::fork();
  if (child < 0) return {};  // no process to spare (memory, limits): the parser tries anyway
  if (child == 0) {
    try {
      cv::FileStorage storage(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
    } catch (...) {
      // An error is an answer: the parser finished.
    }
    ::_exit(0);
  }
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0 && errno != EINTR) return {};  // not ours to judge: let the parser try
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(child, SIGKILL);
      while (::waitpid(child, nullptr, 0) < 0 && errno == EINTR) {
      }
      return fmt::format("OpenCV's {} parser does not finish on it (stopped after {} s)", format,
                         std::chrono::duration<double>(limit).count());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (WIFSIGNALED(status))
    return fmt::format("OpenCV's {} parser crashes on it (signal {})", format, WTERMSIG(status));
  return {};
}

cv::FileStorage OpenFileStorageGuarded(const std::filesystem::path& path, std::string_view format,
                                       std::string_view refused,
                                       std::chrono::milliseconds parse_limit) {
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": no such file");
  std::ifstream file(path, std::ios::binary);
  std::ostringstream buffer;
  buffer << file.rdbuf();
  if (!file) throw InputError(path.string() + ": cannot read");
  const std::string text = std::move(buffer).str();
  std::string problem = YamlNestingProblem(text);
  if (problem.empty()) problem = YamlParserProblem(text, parse_limit, format);
  if (!problem.empty()) throw InputError(fmt::format("{}: {}{}", path.string(), refused, problem));
  const std::string invalid = fmt::format("not valid {}", format);
  cv::FileStorage storage = ReadYamlGuarded(path, invalid.c_str(), [&] {
    return cv::FileStorage(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  });
  if (!storage.isOpened())
    throw InputError(fmt::format("{}: cannot open as {}", path.string(), format));
  return storage;
}

}  // namespace silnet
