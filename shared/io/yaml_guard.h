#pragma once
// A guard for YAML text before OpenCV's FileStorage parses it: the parser recurses once per
// nesting level, so a file of a few hundred kilobytes of brackets or dashes overflows the
// stack and kills the process instead of failing with an error.

#include <string>
#include <string_view>

namespace silnet {

// Deepest nesting accepted: flow collections ('[' and '{', counted wherever they appear, in
// quoted text and comments too) and block indentation (the spaces, tabs and sequence dashes
// that start a line). Far beyond any calibration or job file silnet reads or writes.
inline constexpr int kMaxYamlFlowDepth = 256;
inline constexpr int kMaxYamlIndentColumns = 1024;

// Empty if `text` nests within the limits above, else a reason for the user ("nests flow
// collections 300 deep at line 3 ...").
std::string YamlNestingProblem(std::string_view text);

}  // namespace silnet
