#pragma once
/// @file frame_image.h
/// A rendered frame (RenderImage, what a back-end produces) -> image files
/// through OpenImageIO, atomically: .png: 8-bit colour through the display
/// view (the sky included); .exr: scene-linear half-float R, G, B, A and Z
/// (camera distance, +inf for sky), its header naming the working space.

#include <vfield/render/display_view.h>

#include <OpenImageIO/imagebuf.h>

#include <string>
#include <vector>

namespace vfield {

struct RenderImage {
    int width = 0, height = 0;
    /// Linear RGB premultiplied by A: A is 1 where surfaces or a drawn sky
    /// are seen; with a transparent sky, the coverage by surfaces and cloud
    /// (0 for clear sky, 1 - transmittance through cloud).
    std::vector<float> rgba;
    std::vector<float> depth; ///< camera distance to the first surface; +inf for sky
};

/// A linear value clamped to [0, 1] and sRGB-encoded: how far apart two
/// samples look, whatever the view.
float linearToSrgb(float v);

/// The display image: RGB through the view, floats.
OIIO::ImageBuf toDisplay(const RenderImage& image, const DisplayView& view);
/// The display image of a scene-linear image's first three channels.
OIIO::ImageBuf toDisplay(const OIIO::ImageBuf& linear, const DisplayView& view);
/// The linear RGBAZ image.
OIIO::ImageBuf toLinear(const RenderImage& image);

/// Writes by extension (.png through the view, or .exr). Throws FileError.
void writeFrameImage(const RenderImage& image, const std::string& path, const DisplayView& view);

/// Writes the two image files next to each other (left, then right, tops
/// aligned) into one image at path. Throws FileError.
void writeSideBySide(const std::string& left, const std::string& right, const std::string& path);

} // namespace vfield
