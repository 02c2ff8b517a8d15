#pragma once
/// @file hash.h
/// A 64-bit content hash for comparing what two runs made or read (grid
/// contents, the inputs of a simulation): order-dependent, fast, and the same
/// on every machine. Not cryptographic.

#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

namespace vfield {

class ContentHash {
public:
    /// Mixes the bytes in, 8 at a time (SplitMix64's finalizer per word).
    void add(const void* data, std::size_t size);
    void add(const std::string& text);
    /// A trivially copyable value's bytes (no padding in what is hashed).
    template<typename T>
    void addValue(const T& value)
    {
        static_assert(std::is_trivially_copyable_v<T>, "hash values by their bytes only");
        add(&value, sizeof value);
    }
    uint64_t value() const { return mState; }

private:
    void mix(uint64_t word);
    uint64_t mState = 0x243f6a8885a308d3ull;
};

/// A hash as 16 hexadecimal digits, as files record it.
std::string hashText(uint64_t hash);

} // namespace vfield
