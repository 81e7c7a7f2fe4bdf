#include "shared/io/yaml_nesting.h"

#include <fmt/format.h>

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

}  // namespace silnet
