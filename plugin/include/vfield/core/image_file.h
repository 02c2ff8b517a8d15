#pragma once
/// @file image_file.h
/// Images written through OpenImageIO, atomically (temporary name, rename).

#include <OpenImageIO/imagebuf.h>

#include <string>

namespace vfield {

/// Writes the image in the format its extension names (.png, .exr, ...),
/// converting to the format's pixel type. Throws FileError on failure.
void writeImage(const OIIO::ImageBuf& image, const std::string& path);

} // namespace vfield
