#pragma once
/// @file sample_random.h
/// A counter-based random stream: each (noise stream, pixel, sample) has its own,
/// whatever thread draws it (PCG-style hashing of the counter), so that
/// vfield's integrators give identical images for any thread count.

#include <cstdint>

namespace vfield {

class SampleRandom {
public:
    SampleRandom() = default; ///< a placeholder, to be assigned a sample's stream
    SampleRandom(uint32_t stream, uint32_t pixel, uint32_t sample)
        : mState(hash(hash(hash(stream) ^ pixel) ^ (uint64_t(sample) << 32)))
    {}
    /// Uniform in [0, 1).
    double next() { return double(hash(mState++) >> 11) * (1.0 / 9007199254740992.0); }

private:
    static uint64_t hash(uint64_t x)
    {
        x ^= x >> 33;
        x *= 0xff51afd7ed558ccdull;
        x ^= x >> 33;
        x *= 0xc4ceb9fe1a85ec53ull;
        x ^= x >> 33;
        return x;
    }
    uint64_t mState = 0;
};

} // namespace vfield
