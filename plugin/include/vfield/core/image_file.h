#pragma once
/// @file image_file.h
/// Images written through OpenImageIO, atomically (temporary name, rename),
/// and single planes of numbers read through it (heightmaps).

#include <OpenImageIO/imagebuf.h>

#include <string>
#include <vector>

namespace vfield {

/// Writes the image in the format its extension names (.png, .exr, ...),
/// converting to the format's pixel type: 8 bits, or in an EXR exrType
/// (its depth channel, the spec's z_channel, 32-bit floats whatever that is).
/// Throws FileError on failure.
void writeImage(const OIIO::ImageBuf& image, const std::string& path, OIIO::TypeDesc exrType = OIIO::TypeDesc::HALF);

/// A whole image, every channel as floats (integer formats scaled to [0, 1]).
/// Throws FileError naming the file if it cannot be read.
OIIO::ImageBuf readImageAsFloat(const std::string& path);

/// The first channel of an image, as floats: integer formats scaled to
/// [0, 1] (a 16-bit PNG's 65535 is 1), float formats as stored. Rows top to bottom.
struct ImagePlane {
    int width = 0, height = 0;
    std::vector<float> values; ///< width x height, x fastest
};
/// Throws FileError naming the file if it cannot be read.
ImagePlane readImagePlane(const std::string& path);
/// An image's width and height from its header alone; {0, 0} if it cannot be read.
std::pair<int, int> imageResolution(const std::string& path);

} // namespace vfield
