#pragma once
/// @file povray_runner.h
/// Runs the povray program (POV-Ray 3.7) on a scene file, headless. POV-Ray's
/// I/O restrictions (Debian's /etc/povray/3.7/povray.conf) allow reading and
/// writing in its working folder, so it runs inside the scene's folder and
/// writes its image there.

#include <string>

namespace vfield {

struct PovrayOptions {
    int width = 640, height = 360; ///< pixels
    /// 1: one ray through each pixel's centre; more: n x n supersampling of
    /// every pixel with n = round(sqrt(samplesPerPixel)), at most 9.
    int samplesPerPixel = 4;
    /// Render threads. POV-Ray's media sampling differs between thread counts;
    /// 1 makes its images reproducible.
    int threads = 1;
};

/// Renders folder/sceneFile to folder/imageFile (8-bit sRGB PNG). POV-Ray's
/// output goes to folder/<imageFile>.log. Throws Error when povray is not on
/// PATH (naming the Debian package) and when it fails (with the last lines of
/// its log and the log's path).
void runPovray(const std::string& folder, const std::string& sceneFile, const std::string& imageFile,
               const PovrayOptions& options);

/// Whether a povray program is on PATH.
bool povrayAvailable();
/// Throws Error naming the Debian package when povray is not on PATH.
void requirePovray();

} // namespace vfield
