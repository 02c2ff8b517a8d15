#include <vfield/core/frame_file.h>

#include <cstdio>

namespace vfield {

std::string frameFileName(const std::string& stem, int frame, const std::string& extension)
{
    char number[16];
    std::snprintf(number, sizeof number, "%04d", frame);
    return stem + "." + number + "." + extension;
}

} // namespace vfield
