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
    /// A stream of its own for each key, split off this one by a single draw:
    /// what is drawn from the keyed streams does not shift this one's later
    /// draws, nor one key's draws another's.
    class Split {
    public:
        SampleRandom operator()(uint64_t key) const
        {
            SampleRandom keyed;
            keyed.mState = hash(mSeed ^ hash(key));
            return keyed;
        }

    private:
        friend class SampleRandom;
        explicit Split(uint64_t seed) : mSeed(seed) {}
        uint64_t mSeed;
    };
    Split split() { return Split(hash(mState++)); }

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
