#pragma once
/// @file frame_image.h
/// RenderImage -> image files through OpenImageIO, atomically:
/// .png: 8-bit sRGB colour (the sky included); .exr: linear half-float
/// R, G, B, A and Z (camera distance, +inf for sky).

#include <vfield/render/renderer.h>

#include <OpenImageIO/imagebuf.h>

#include <string>

namespace vfield {

/// The display image: sRGB-encoded RGB, floats in [0, 1].
OIIO::ImageBuf toDisplay(const RenderImage& image);
/// The linear RGBAZ image.
OIIO::ImageBuf toLinear(const RenderImage& image);

/// Writes by extension (.png or .exr). Throws FileError.
void writeFrameImage(const RenderImage& image, const std::string& path);

/// Writes the two image files next to each other (left, then right, tops
/// aligned) into one image at path. Throws FileError.
void writeSideBySide(const std::string& left, const std::string& right, const std::string& path);

} // namespace vfield
