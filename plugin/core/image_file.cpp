#include <vfield/core/image_file.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <algorithm>

namespace vfield {

void writeImage(const OIIO::ImageBuf& image, const std::string& path)
{
    writeFileAtomically(path, [&](const std::string& temporary) {
        std::string lower = path;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        const bool isExr = lower.size() > 4 && lower.compare(lower.size() - 4, 4, ".exr") == 0;
        const OIIO::TypeDesc type = isExr ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8;
        if (!image.write(temporary, type)) {
            std::string why = image.geterror();
            std::replace(why.begin(), why.end(), '\n', ' ');
            throw FileError(path, "cannot write image: " + why);
        }
    });
}

} // namespace vfield
