#include <vfield/core/noise.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace vfield {

namespace {

float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
float lerp(float a, float b, float t) { return a + t * (b - a); }

float gradient2(int h, float x, float y)
{
    static constexpr float kDirections[8][2] = {{1, 0},
                                                {-1, 0},
                                                {0, 1},
                                                {0, -1},
                                                {0.70710678f, 0.70710678f},
                                                {-0.70710678f, 0.70710678f},
                                                {0.70710678f, -0.70710678f},
                                                {-0.70710678f, -0.70710678f}};
    return kDirections[h & 7][0] * x + kDirections[h & 7][1] * y;
}

/// The twelve edge directions of a cube (Perlin 2002), four repeated.
float gradient3(int h, float x, float y, float z)
{
    switch (h & 15) {
    case 0:
        return x + y;
    case 1:
        return -x + y;
    case 2:
        return x - y;
    case 3:
        return -x - y;
    case 4:
        return x + z;
    case 5:
        return -x + z;
    case 6:
        return x - z;
    case 7:
        return -x - z;
    case 8:
        return y + z;
    case 9:
        return -y + z;
    case 10:
        return y - z;
    case 11:
        return -y - z;
    case 12:
        return x + y;
    case 13:
        return -y + z;
    case 14:
        return -x + y;
    default:
        return -y - z;
    }
}

} // namespace

GradientNoise::GradientNoise(uint64_t seed)
{
    std::mt19937_64 random(seed);
    for (int i = 0; i < 256; ++i) mPermutation[i] = static_cast<uint8_t>(i);
    for (int i = 255; i > 0; --i) std::swap(mPermutation[i], mPermutation[random() % uint64_t(i + 1)]);
}

float GradientNoise::operator()(float x, float y) const
{
    const float fx = std::floor(x), fy = std::floor(y);
    const int ix = int(fx), iy = int(fy);
    const float dx = x - fx, dy = y - fy;
    const float u = fade(dx), v = fade(dy);
    const int a = hash(ix) + iy, b = hash(ix + 1) + iy;
    const float n00 = gradient2(hash(a), dx, dy), n10 = gradient2(hash(b), dx - 1, dy);
    const float n01 = gradient2(hash(a + 1), dx, dy - 1), n11 = gradient2(hash(b + 1), dx - 1, dy - 1);
    return lerp(lerp(n00, n10, u), lerp(n01, n11, u), v) * 1.41421356f;
}

float GradientNoise::operator()(float x, float y, float z) const
{
    const float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const int ix = int(fx), iy = int(fy), iz = int(fz);
    const float dx = x - fx, dy = y - fy, dz = z - fz;
    const float u = fade(dx), v = fade(dy), w = fade(dz);
    const int a = hash(ix) + iy, aa = hash(a) + iz, ab = hash(a + 1) + iz;
    const int b = hash(ix + 1) + iy, ba = hash(b) + iz, bb = hash(b + 1) + iz;
    const float x0 = lerp(gradient3(hash(aa), dx, dy, dz), gradient3(hash(ba), dx - 1, dy, dz), u);
    const float x1 = lerp(gradient3(hash(ab), dx, dy - 1, dz), gradient3(hash(bb), dx - 1, dy - 1, dz), u);
    const float x2 = lerp(gradient3(hash(aa + 1), dx, dy, dz - 1), gradient3(hash(ba + 1), dx - 1, dy, dz - 1), u);
    const float x3 = lerp(gradient3(hash(ab + 1), dx, dy - 1, dz - 1), gradient3(hash(bb + 1), dx - 1, dy - 1, dz - 1), u);
    return lerp(lerp(x0, x1, v), lerp(x2, x3, v), w);
}

float fbm(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options)
{
    float sum = 0.0f, amplitude = 1.0f, total = 0.0f, frequency = 1.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        // Offset each octave so that lattice zeros do not line up.
        const float shift = 17.31f * float(octave);
        sum += amplitude * noise(p[0] * frequency + shift, p[1] * frequency - shift, p[2] * frequency + 0.5f * shift);
        total += amplitude;
        amplitude *= float(options.gain);
        frequency *= float(options.lacunarity);
    }
    return sum / total;
}

float fbm(const GradientNoise& noise, float x, float y, const FractalOptions& options)
{
    float sum = 0.0f, amplitude = 1.0f, total = 0.0f, frequency = 1.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        const float shift = 17.31f * float(octave);
        sum += amplitude * noise(x * frequency + shift, y * frequency - 9.73f * float(octave));
        total += amplitude;
        amplitude *= float(options.gain);
        frequency *= float(options.lacunarity);
    }
    return sum / total;
}

float ridgedMultifractal(const GradientNoise& noise, float x, float y, const FractalOptions& options)
{
    // Musgrave's formulation: offset 1, each octave's weight the previous
    // octave's signal times 2, clamped to [0, 1].
    float sum = 0.0f, total = 0.0f, weight = 1.0f, amplitude = 1.0f, frequency = 1.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        const float shift = 17.31f * float(octave);
        float signal = 1.0f - std::abs(noise(x * frequency + shift, y * frequency - 9.73f * float(octave)));
        signal *= signal * weight;
        weight = std::clamp(2.0f * signal, 0.0f, 1.0f);
        sum += signal * amplitude;
        total += amplitude;
        amplitude *= float(options.gain);
        frequency *= float(options.lacunarity);
    }
    return sum / total;
}

} // namespace vfield
