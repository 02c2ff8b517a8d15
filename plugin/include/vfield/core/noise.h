#pragma once
/// @file noise.h
/// Seeded gradient noise (Perlin's improved noise) in 2D and 3D, and the
/// fractal sums built from it: fBm and ridged multifractal. The terrain, the
/// cloud's detail and the surfaces' shading all draw from it. The permutation
/// comes from std::mt19937_64, whose output the standard fixes, so a seed
/// gives the same values on every machine.

#include <vfield/core/math.h>

#include <array>
#include <cstddef>
#include <cstdint>

namespace vfield {

/// A noise value and its gradient (d value / d p).
struct NoiseSample {
    float value = 0.0f;
    Vec3f gradient{0.0f};
};

class GradientNoise {
public:
    explicit GradientNoise(uint64_t seed);

    /// Values in about [-1, 1], zero at integer lattice points; period 256.
    float operator()(float x, float y) const;
    float operator()(float x, float y, float z) const;
    /// Four 3D values at once, each bit for bit operator()(x[i], y[i], z[i])
    /// (SIMD lanes, twice as fast): the fractal sums below take their
    /// octaves four at a time.
    std::array<float, 4> operator()(const std::array<float, 4>& x, const std::array<float, 4>& y,
                                    const std::array<float, 4>& z) const;
    /// The 3D value (equal to operator() but for rounding) with its exact gradient.
    NoiseSample sample(const Vec3f& p) const;
    /// Four at once, each bit for bit sample(p[i]) (SIMD lanes; each sample
    /// in about three quarters of the time, since the lattice's hashes stay
    /// scalar): turbulence takes its octaves' reads four at a time.
    std::array<NoiseSample, 4> sample(const std::array<Vec3f, 4>& p) const;

private:
    int hash(int x) const { return mPermutation[x & 255]; }
    /// The hashes of a lattice cell's eight corners (000, 100, 010, 110, 001,
    /// 101, 011, 111 by their x y z offsets) from its lowest corner.
    std::array<int, 8> cornerHashes(int ix, int iy, int iz) const;
    std::array<uint8_t, 256> mPermutation{};
};

/// How octaves of noise add up.
struct FractalOptions {
    int octaves = 4;         ///< (1..16)
    double lacunarity = 2.0; ///< frequency ratio of successive octaves
    double gain = 0.5;       ///< amplitude ratio of successive octaves (0..1)
};

/// Fractional Brownian motion: the sum of octaves, normalised to about [-1, 1].
float fbm(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options);
float fbm(const GradientNoise& noise, float x, float y, const FractalOptions& options);
/// One fbm sum among several evaluated at once.
struct FbmQuery {
    Vec3f point;
    FractalOptions options;
};
/// At most this many octaves, summed over their queries, one batched call
/// below evaluates.
constexpr int kMaxBatchOctaves = 64;
/// values[i] = fbm(noise, queries[i].point, queries[i].options), bit for
/// bit, with the octaves of all count queries evaluated together, four at a
/// time (at most kMaxBatchOctaves in all; ValueError beyond).
void fbm(const GradientNoise& noise, const FbmQuery* queries, std::size_t count, float* values);
/// fbm in 3D with its exact gradient, with respect to p.
NoiseSample fbmSample(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options);
/// Billow noise (libnoise's name), about [0, 1]: octaves of |noise|, so the
/// pattern is rounded lumps with sharp creases between them where the noise
/// crosses zero: cauliflower, the outline of a cumulus.
float billow(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options);
/// values[i] = billow(noise, queries[i].point, queries[i].options), bit for
/// bit, batched as fbm's: a sum of three octaves alone leaves a lane idle.
void billow(const GradientNoise& noise, const FbmQuery* queries, std::size_t count, float* values);

/// Musgrave's ridged multifractal in 2D, about [0, 1]: sharp crests where the
/// noise crosses zero, each octave weighted by the one before, so crests carry
/// detail and the valleys between them stay smooth.
float ridgedMultifractal(const GradientNoise& noise, float x, float y, const FractalOptions& options);

} // namespace vfield
