#include <vfield/core/file_tail.h>

#include <algorithm>
#include <fstream>

namespace vfield {

std::string fileTail(const std::string& path, std::size_t maxBytes)
{
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) return "";
    const std::streamoff size = in.tellg();
    const std::streamoff start = std::max<std::streamoff>(0, size - std::streamoff(maxBytes));
    in.seekg(start);
    std::string tail(std::size_t(size - start), '\0');
    in.read(tail.data(), size - start);
    tail.resize(std::size_t(in.gcount()));
    return tail;
}

} // namespace vfield
