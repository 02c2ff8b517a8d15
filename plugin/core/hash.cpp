#include <vfield/core/hash.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace vfield {

void ContentHash::add(const void* data, std::size_t size)
{
    const auto* bytes = static_cast<const unsigned char*>(data);
    while (size > 0) {
        uint64_t word = 0;
        const std::size_t n = std::min<std::size_t>(size, 8);
        std::memcpy(&word, bytes, n);
        mix(word ^ (uint64_t(n) << 56));
        bytes += n;
        size -= n;
    }
}

void ContentHash::add(const std::string& text) { add(text.data(), text.size()); }

void ContentHash::mix(uint64_t word)
{
    uint64_t z = (mState ^ word) + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    mState = z ^ (z >> 31);
}

std::string hashText(uint64_t hash)
{
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
    return text;
}

} // namespace vfield
