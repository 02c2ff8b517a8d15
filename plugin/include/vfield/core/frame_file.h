#pragma once
/// @file frame_file.h
/// How vfield names a file of one frame of a sequence: "stem.####.ext", the
/// frame number padded to four digits, as Houdini, Nuke and ffmpeg read them.

#include <string>

namespace vfield {

/// "density.0007.vdb" for ("density", 7, "vdb").
std::string frameFileName(const std::string& stem, int frame, const std::string& extension);

} // namespace vfield
