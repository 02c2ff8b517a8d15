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
constexpr float kCubeEdges[16][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                     {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                                     {1, 1, 0},  {0, -1, 1},  {-1, 1, 0}, {0, -1, -1}};

float gradient3(int h, float x, float y, float z)
{
    const float* g = kCubeEdges[h & 15];
    return g[0] * x + g[1] * y + g[2] * z;
}

/// The derivative of fade.
float fadeDerivative(float t) { return 30.0f * t * t * (t - 1.0f) * (t - 1.0f); }

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

NoiseSample GradientNoise::sample(const Vec3f& p) const
{
    const float fx = std::floor(p[0]), fy = std::floor(p[1]), fz = std::floor(p[2]);
    const int ix = int(fx), iy = int(fy), iz = int(fz);
    const float dx = p[0] - fx, dy = p[1] - fy, dz = p[2] - fz;
    const float u = fade(dx), v = fade(dy), w = fade(dz);
    const float du = fadeDerivative(dx), dv = fadeDerivative(dy), dw = fadeDerivative(dz);
    const int a = hash(ix) + iy, aa = hash(a) + iz, ab = hash(a + 1) + iz;
    const int b = hash(ix + 1) + iy, ba = hash(b) + iz, bb = hash(b + 1) + iz;
    // The corners' gradients, named by their offsets (x y z), as operator() hashes them.
    const float* g000 = kCubeEdges[hash(aa) & 15];
    const float* g100 = kCubeEdges[hash(ba) & 15];
    const float* g010 = kCubeEdges[hash(ab) & 15];
    const float* g110 = kCubeEdges[hash(bb) & 15];
    const float* g001 = kCubeEdges[hash(aa + 1) & 15];
    const float* g101 = kCubeEdges[hash(ba + 1) & 15];
    const float* g011 = kCubeEdges[hash(ab + 1) & 15];
    const float* g111 = kCubeEdges[hash(bb + 1) & 15];
    const auto ramp = [](const float* g, float x, float y, float z) { return g[0] * x + g[1] * y + g[2] * z; };
    const float n000 = ramp(g000, dx, dy, dz), n100 = ramp(g100, dx - 1, dy, dz);
    const float n010 = ramp(g010, dx, dy - 1, dz), n110 = ramp(g110, dx - 1, dy - 1, dz);
    const float n001 = ramp(g001, dx, dy, dz - 1), n101 = ramp(g101, dx - 1, dy, dz - 1);
    const float n011 = ramp(g011, dx, dy - 1, dz - 1), n111 = ramp(g111, dx - 1, dy - 1, dz - 1);
    // The value as a polynomial in the fades; its gradient adds the fades'
    // derivatives times that polynomial's partials to the blend of the gradients.
    const float k1 = n100 - n000, k2 = n010 - n000, k3 = n001 - n000;
    const float k4 = n000 - n100 - n010 + n110, k5 = n000 - n010 - n001 + n011, k6 = n000 - n100 - n001 + n101;
    const float k7 = -n000 + n100 + n010 - n110 + n001 - n101 - n011 + n111;
    NoiseSample s;
    s.value = n000 + k1 * u + k2 * v + k3 * w + k4 * u * v + k5 * v * w + k6 * w * u + k7 * u * v * w;
    for (int axis = 0; axis < 3; ++axis) {
        const float x0 = g000[axis] + (g100[axis] - g000[axis]) * u, x1 = g010[axis] + (g110[axis] - g010[axis]) * u;
        const float x2 = g001[axis] + (g101[axis] - g001[axis]) * u, x3 = g011[axis] + (g111[axis] - g011[axis]) * u;
        const float y0 = x0 + (x1 - x0) * v, y1 = x2 + (x3 - x2) * v;
        s.gradient[axis] = y0 + (y1 - y0) * w;
    }
    s.gradient += Vec3f(du * (k1 + k4 * v + k6 * w + k7 * v * w), dv * (k2 + k4 * u + k5 * w + k7 * u * w),
                        dw * (k3 + k5 * v + k6 * u + k7 * u * v));
    return s;
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

NoiseSample fbmSample(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options)
{
    NoiseSample sum;
    float amplitude = 1.0f, total = 0.0f, frequency = 1.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        const float shift = 17.31f * float(octave); // as in fbm
        const NoiseSample octaveSample =
            noise.sample(Vec3f(p[0] * frequency + shift, p[1] * frequency - shift, p[2] * frequency + 0.5f * shift));
        sum.value += amplitude * octaveSample.value;
        sum.gradient += octaveSample.gradient * (amplitude * frequency);
        total += amplitude;
        amplitude *= float(options.gain);
        frequency *= float(options.lacunarity);
    }
    sum.value /= total;
    sum.gradient /= total;
    return sum;
}

float billow(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options)
{
    float sum = 0.0f, amplitude = 1.0f, total = 0.0f, frequency = 1.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        const float shift = 17.31f * float(octave); // as in fbm
        sum += amplitude * std::abs(noise(p[0] * frequency + shift, p[1] * frequency - shift, p[2] * frequency + 0.5f * shift));
        total += amplitude;
        amplitude *= float(options.gain);
        frequency *= float(options.lacunarity);
    }
    // |noise| averages about a quarter and seldom passes a half: doubled, the
    // sum spans about [0, 1].
    return std::min(1.0f, 2.0f * sum / total);
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
