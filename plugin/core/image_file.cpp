#include <vfield/core/image_file.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <vector>

namespace vfield {

void writeImage(const OIIO::ImageBuf& image, const std::string& path, OIIO::TypeDesc exrType)
{
    writeFileAtomically(path, [&](const std::string& temporary) {
        std::string lower = path;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        const bool isExr = lower.size() > 4 && lower.compare(lower.size() - 4, 4, ".exr") == 0;
        // A depth channel as 32-bit floats whatever the colours are, since
        // half keeps only 11 bits (0.25 units of precision at 300 units).
        std::vector<OIIO::TypeDesc> formats(std::size_t(image.nchannels()), isExr ? exrType : OIIO::TypeDesc::UINT8);
        if (isExr && image.spec().z_channel >= 0) formats[std::size_t(image.spec().z_channel)] = OIIO::TypeDesc::FLOAT;
        OIIO::ImageBuf out(image.spec());
        out.copy_pixels(image);
        out.set_write_format(formats);
        // zlib level 3 with the Sub filter: a frame in about a third of the
        // default's time, for a file a few percent larger.
        out.specmod().attribute("png:compressionLevel", 3);
        out.specmod().attribute("png:filter", 0x10); // PNG_FILTER_SUB
        if (!out.write(temporary)) {
            std::string why = image.geterror();
            std::replace(why.begin(), why.end(), '\n', ' ');
            throw FileError(path, "cannot write image: " + why);
        }
    });
}

OIIO::ImageBuf readImageAsFloat(const std::string& path)
{
    OIIO::ImageBuf image(path);
    if (!image.read(0, 0, true, OIIO::TypeDesc::FLOAT)) throw FileError(path, "cannot read the image: " + image.geterror());
    return image;
}

ImagePlane readImagePlane(const std::string& path)
{
    auto input = OIIO::ImageInput::open(path);
    if (!input) {
        std::string why = OIIO::geterror();
        std::replace(why.begin(), why.end(), '\n', ' ');
        throw FileError(path, "cannot read image: " + why);
    }
    const OIIO::ImageSpec& spec = input->spec();
    ImagePlane plane;
    plane.width = spec.width;
    plane.height = spec.height;
    plane.values.resize(std::size_t(spec.width) * std::size_t(spec.height));
    if (!input->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, plane.values.data())) {
        std::string why = input->geterror();
        std::replace(why.begin(), why.end(), '\n', ' ');
        throw FileError(path, "cannot read image: " + why);
    }
    return plane;
}

std::pair<int, int> imageResolution(const std::string& path)
{
    const auto input = OIIO::ImageInput::open(path);
    if (!input) {
        OIIO::geterror(); // clear it: the caller reads the file later and reports then
        return {0, 0};
    }
    return {input->spec().width, input->spec().height};
}

} // namespace vfield
