#pragma once
/// @file povray_runner.h
/// Runs the povray program (POV-Ray 3.7) on a scene file, headless. POV-Ray's
/// I/O restrictions (Debian's /etc/povray/3.7/povray.conf) allow reading and
/// writing in its working folder, so it runs inside the scene's folder and
/// writes its image there.

#include <vfield/render/povray/povray_settings.h>
#include <vfield/render/render_settings.h>

#include <functional>
#include <optional>
#include <string>

namespace vfield {

/// Renders folder/sceneFile to folder/imageFile (OpenEXR: scene-linear light,
/// which the back-end shows through the display view) at the image's size. samplesPerPixel 1 traces one ray through each pixel's
/// centre; more supersample every pixel on an n x n grid, n = round(sqrt(samples)), at most 9 (PovrayQuality::Final), or only
/// pixels that differ from their neighbours, 2 x 2 (Preview). threads: POV-Ray's render threads (>= 1); its media sampling
/// differs between thread counts, and 1 makes its images reproducible.
/// POV-Ray's output goes to folder/<imageFile>.log; progress, if set, is told
/// the fraction of pixels POV-Ray reports rendered (from the calling thread)
/// as it grows, and at least once a second. Throws Error when povray
/// is not on PATH (naming the Debian package) and when it fails (with the last
/// lines of its log and the log's path).
void runPovray(const std::string& folder, const std::string& sceneFile, const std::string& imageFile, const ImageSettings& image,
               PovrayQuality quality, int threads, const std::function<void(double fraction)>& progress = {});

/// Whether a povray program is on PATH.
bool povrayAvailable();
/// Throws Error naming the Debian package when povray is not on PATH.
void requirePovray();
/// The version the povray program on PATH reports ("3.7.0.10.unofficial"),
/// the one runPovray would run; nothing when there is none or it names none.
std::optional<std::string> povrayVersion();

} // namespace vfield
