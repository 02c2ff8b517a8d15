// find_images SCREENSHOT IMAGE...: exits 0 when every IMAGE appears in the
// screenshot at 1:1 (each pixel within 3 8-bit steps per channel), else names
// the missing ones and exits 1. How the report's browser test checks that a
// page shows the images it should.

#include <OpenImageIO/imagebuf.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

struct Rgb8 {
    int width = 0, height = 0;
    std::vector<unsigned char> pixels; ///< RGB, row by row
    int at(int x, int y, int c) const { return pixels[(std::size_t(y) * width + x) * 3 + c]; }
};

Rgb8 readRgb8(const char* path)
{
    OIIO::ImageBuf image(path);
    if (!image.read(0, 0, true, OIIO::TypeDesc::UINT8)) {
        std::fprintf(stderr, "find_images: %s: %s\n", path, image.geterror().c_str());
        std::exit(2);
    }
    Rgb8 rgb;
    rgb.width = image.spec().width;
    rgb.height = image.spec().height;
    rgb.pixels.resize(std::size_t(rgb.width) * rgb.height * 3);
    image.get_pixels(OIIO::ROI(0, rgb.width, 0, rgb.height, 0, 1, 0, 3), OIIO::TypeDesc::UINT8, rgb.pixels.data());
    return rgb;
}

bool matchesAt(const Rgb8& screen, const Rgb8& image, int x0, int y0)
{
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c)
                if (std::abs(screen.at(x0 + x, y0 + y, c) - image.at(x, y, c)) > 3) return false;
    return true;
}

bool appears(const Rgb8& screen, const Rgb8& image)
{
    for (int y = 0; y + image.height <= screen.height; ++y)
        for (int x = 0; x + image.width <= screen.width; ++x)
            if (matchesAt(screen, image, x, y)) return true;
    return false;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: find_images SCREENSHOT IMAGE...\n");
        return 2;
    }
    const Rgb8 screen = readRgb8(argv[1]);
    int missing = 0;
    for (int i = 2; i < argc; ++i)
        if (!appears(screen, readRgb8(argv[i]))) {
            std::fprintf(stderr, "find_images: %s does not appear in %s\n", argv[i], argv[1]);
            ++missing;
        }
    return missing == 0 ? 0 : 1;
}
