#include <vfield/core/image_file.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <algorithm>
#include <vector>

namespace vfield {

void writeImage(const OIIO::ImageBuf& image, const std::string& path)
{
    writeFileAtomically(path, [&](const std::string& temporary) {
        std::string lower = path;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        const bool isExr = lower.size() > 4 && lower.compare(lower.size() - 4, 4, ".exr") == 0;
        // EXR: colours as half floats; a depth channel as 32-bit floats, since
        // half keeps only 11 bits (0.25 units of precision at 300 units).
        std::vector<OIIO::TypeDesc> formats(std::size_t(image.nchannels()), isExr ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
        if (isExr && image.spec().z_channel >= 0) formats[std::size_t(image.spec().z_channel)] = OIIO::TypeDesc::FLOAT;
        OIIO::ImageBuf out(image.spec());
        out.copy_pixels(image);
        out.set_write_format(formats);
        if (!out.write(temporary)) {
            std::string why = image.geterror();
            std::replace(why.begin(), why.end(), '\n', ' ');
            throw FileError(path, "cannot write image: " + why);
        }
    });
}

} // namespace vfield
