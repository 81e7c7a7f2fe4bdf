#pragma once
// What a COMMAND_CAPTURE_STILL asks for besides a still of the subject, in its parameter
// (idl/silnet.idl): parameter {kStillKind, kBackgroundStill} asks for a still of the empty
// scene, which the node keeps as the background of its later full-resolution stills.

namespace silnet::dds {

inline constexpr const char* kStillKind = "still";
inline constexpr const char* kBackgroundStill = "background";

}  // namespace silnet::dds
