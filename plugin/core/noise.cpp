#include <vfield/core/noise.h>

#include <vfield/core/error.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>

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

// Four lanes (GCC's and Clang's vector extensions: SSE2 on x86-64). Every
// operation is the scalar code's, in its order, so each lane is bit for bit
// the scalar value.
using Floats4 = float __attribute__((vector_size(16)));
using Ints4 = int32_t __attribute__((vector_size(16)));
using Bits4 = uint32_t __attribute__((vector_size(16)));

Floats4 fade(Floats4 t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
Floats4 lerp(Floats4 a, Floats4 b, Floats4 t) { return a + t * (b - a); }

/// floor(t), and as integers in i.
Floats4 floor(Floats4 t, Ints4& i)
{
    i = __builtin_convertvector(t, Ints4);                 // towards zero
    i += (Ints4)(__builtin_convertvector(i, Floats4) > t); // rounded up (t < 0): one less
    return __builtin_convertvector(i, Floats4);
}

/// gradient3 without its table (Perlin 2002's bit form of the same
/// directions): +-u +- v, u and v two of x, y, z by the hash's bits. The
/// table's zero component adds a zero, which changes no sum.
Floats4 gradient3(Ints4 h, Floats4 x, Floats4 y, Floats4 z)
{
    h &= 15;
    const Ints4 uIsX = h < 8, vIsY = h < 4, vIsX = (h == 12) | (h == 14);
    const Floats4 u = (Floats4)(((Ints4)x & uIsX) | ((Ints4)y & ~uIsX));
    const Floats4 v = (Floats4)(((Ints4)y & vIsY) | ((Ints4)x & (vIsX & ~vIsY)) | ((Ints4)z & ~(vIsY | vIsX)));
    const Bits4 flipU = (Bits4)(h & 1) << 31, flipV = (Bits4)(h & 2) << 30; // sign bits
    return (Floats4)((Bits4)u ^ flipU) + (Floats4)((Bits4)v ^ flipV);
}

Floats4 fadeDerivative(Floats4 t) { return 30.0f * t * t * (t - 1.0f) * (t - 1.0f); }

/// Four samples' values and gradients from their offsets (dx, dy, dz) in
/// their lattice cells and the gradients g[corner][axis] at the cells'
/// corners (000, 100, 010, 110, 001, 101, 011, 111, by their x y z offsets):
/// GradientNoise::sample's expression, operation for operation, so that each
/// lane is bit for bit its sample. Not shared with it as a template: the
/// scalar sample made from one is markedly slower.
void cellSample(const Floats4 (&g)[8][3], Floats4 dx, Floats4 dy, Floats4 dz, Floats4& value, Floats4 (&gradient)[3])
{
    using F = Floats4;
    const F u = fade(dx), v = fade(dy), w = fade(dz);
    const F du = fadeDerivative(dx), dv = fadeDerivative(dy), dw = fadeDerivative(dz);
    const auto ramp = [&g](int corner, F x, F y, F z) { return g[corner][0] * x + g[corner][1] * y + g[corner][2] * z; };
    const F dx1 = dx - 1.0f, dy1 = dy - 1.0f, dz1 = dz - 1.0f;
    const F n000 = ramp(0, dx, dy, dz), n100 = ramp(1, dx1, dy, dz);
    const F n010 = ramp(2, dx, dy1, dz), n110 = ramp(3, dx1, dy1, dz);
    const F n001 = ramp(4, dx, dy, dz1), n101 = ramp(5, dx1, dy, dz1);
    const F n011 = ramp(6, dx, dy1, dz1), n111 = ramp(7, dx1, dy1, dz1);
    // The value as a polynomial in the fades; its gradient adds the fades'
    // derivatives times that polynomial's partials to the blend of the gradients.
    const F k1 = n100 - n000, k2 = n010 - n000, k3 = n001 - n000;
    const F k4 = n000 - n100 - n010 + n110, k5 = n000 - n010 - n001 + n011, k6 = n000 - n100 - n001 + n101;
    const F k7 = -n000 + n100 + n010 - n110 + n001 - n101 - n011 + n111;
    value = n000 + k1 * u + k2 * v + k3 * w + k4 * u * v + k5 * v * w + k6 * w * u + k7 * u * v * w;
    for (int axis = 0; axis < 3; ++axis) {
        const F x0 = g[0][axis] + (g[1][axis] - g[0][axis]) * u, x1 = g[2][axis] + (g[3][axis] - g[2][axis]) * u;
        const F x2 = g[4][axis] + (g[5][axis] - g[4][axis]) * u, x3 = g[6][axis] + (g[7][axis] - g[6][axis]) * u;
        const F y0 = x0 + (x1 - x0) * v, y1 = x2 + (x3 - x2) * v;
        gradient[axis] = y0 + (y1 - y0) * w;
    }
    gradient[0] += du * (k1 + k4 * v + k6 * w + k7 * v * w);
    gradient[1] += dv * (k2 + k4 * u + k5 * w + k7 * u * w);
    gradient[2] += dw * (k3 + k5 * v + k6 * u + k7 * u * v);
}

/// At most this many octaves a fractal sum takes (FractalOptions::octaves);
/// kMaxBatchOctaves (noise.h) bounds those of several sums evaluated together.
constexpr int kMaxOctaves = 16;

/// The noise of each octave of the fBm queries, as fbm samples them, one
/// query after another in values: four lanes at a time, the last run of one
/// octave alone.
void octaveNoise(const GradientNoise& noise, const FbmQuery* queries, std::size_t count, float* values)
{
    // Three past the last: a run of four starting at any octave stays inside.
    std::array<float, kMaxBatchOctaves + 3> x, y, z;
    int octaves = 0;
    for (std::size_t q = 0; q < count; ++q) {
        const FractalOptions& options = queries[q].options;
        if (options.octaves > kMaxOctaves || octaves + options.octaves > kMaxBatchOctaves)
            throw ValueError("fractal noise of more than " + std::to_string(kMaxOctaves) + " octaves, or " +
                             std::to_string(kMaxBatchOctaves) + " at once");
        const Vec3f& p = queries[q].point;
        float frequency = 1.0f;
        for (int octave = 0; octave < options.octaves; ++octave, ++octaves) {
            // Offset each octave so that lattice zeros do not line up.
            const float shift = 17.31f * float(octave);
            x[octaves] = p[0] * frequency + shift;
            y[octaves] = p[1] * frequency - shift;
            z[octaves] = p[2] * frequency + 0.5f * shift;
            frequency *= float(options.lacunarity);
        }
    }
    // Lanes past the last octave read zeros, unused (set only those: the
    // whole arrays cost as much as a noise value to clear).
    std::fill_n(x.begin() + octaves, 3, 0.0f);
    std::fill_n(y.begin() + octaves, 3, 0.0f);
    std::fill_n(z.begin() + octaves, 3, 0.0f);
    int octave = 0;
    for (; octaves - octave >= 2; octave += 4) {
        std::array<float, 4> lx, ly, lz;
        std::memcpy(lx.data(), &x[octave], sizeof(lx));
        std::memcpy(ly.data(), &y[octave], sizeof(ly));
        std::memcpy(lz.data(), &z[octave], sizeof(lz));
        const std::array<float, 4> lanes = noise(lx, ly, lz);
        std::copy_n(lanes.begin(), std::min(4, octaves - octave), values + octave);
    }
    for (; octave < octaves; ++octave) values[octave] = noise(x[octave], y[octave], z[octave]);
}

/// fbm's sum of one query's octave noise.
float fbmSum(const float* values, const FractalOptions& options)
{
    float sum = 0.0f, amplitude = 1.0f, total = 0.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        sum += amplitude * values[octave];
        total += amplitude;
        amplitude *= float(options.gain);
    }
    return sum / total;
}

/// billow's sum of one query's octave noise.
float billowSum(const float* values, const FractalOptions& options)
{
    float sum = 0.0f, amplitude = 1.0f, total = 0.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        sum += amplitude * std::abs(values[octave]);
        total += amplitude;
        amplitude *= float(options.gain);
    }
    // |noise| averages about a quarter and seldom passes a half: doubled, the
    // sum spans about [0, 1].
    return std::min(1.0f, 2.0f * sum / total);
}

/// Each query's octave noise (octaveNoise, all the queries' together),
/// summed by sum(its octaves' values, its options): fbmSum or billowSum.
template<typename Sum>
void fractalSums(const GradientNoise& noise, const FbmQuery* queries, std::size_t count, float* values, Sum sum)
{
    float octaves[kMaxBatchOctaves];
    octaveNoise(noise, queries, count, octaves);
    for (std::size_t q = 0, first = 0; q < count; first += std::size_t(queries[q].options.octaves), ++q)
        values[q] = sum(octaves + first, queries[q].options);
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

std::array<float, 4> GradientNoise::operator()(const std::array<float, 4>& px, const std::array<float, 4>& py,
                                               const std::array<float, 4>& pz) const
{
    Floats4 x, y, z;
    std::memcpy(&x, px.data(), sizeof(x));
    std::memcpy(&y, py.data(), sizeof(y));
    std::memcpy(&z, pz.data(), sizeof(z));
    Ints4 ix, iy, iz;
    const Floats4 dx = x - floor(x, ix), dy = y - floor(y, iy), dz = z - floor(z, iz);
    const Floats4 u = fade(dx), v = fade(dy), w = fade(dz);
    // The corners' hashes, lane by lane (no gather in SSE2), as the scalar code chains them.
    Ints4 h000, h100, h010, h110, h001, h101, h011, h111;
    for (int lane = 0; lane < 4; ++lane) {
        const int a = hash(ix[lane]) + iy[lane], aa = hash(a) + iz[lane], ab = hash(a + 1) + iz[lane];
        const int b = hash(ix[lane] + 1) + iy[lane], ba = hash(b) + iz[lane], bb = hash(b + 1) + iz[lane];
        h000[lane] = hash(aa);
        h100[lane] = hash(ba);
        h010[lane] = hash(ab);
        h110[lane] = hash(bb);
        h001[lane] = hash(aa + 1);
        h101[lane] = hash(ba + 1);
        h011[lane] = hash(ab + 1);
        h111[lane] = hash(bb + 1);
    }
    const Floats4 dx1 = dx - 1.0f, dy1 = dy - 1.0f, dz1 = dz - 1.0f;
    const Floats4 x0 = lerp(gradient3(h000, dx, dy, dz), gradient3(h100, dx1, dy, dz), u);
    const Floats4 x1 = lerp(gradient3(h010, dx, dy1, dz), gradient3(h110, dx1, dy1, dz), u);
    const Floats4 x2 = lerp(gradient3(h001, dx, dy, dz1), gradient3(h101, dx1, dy, dz1), u);
    const Floats4 x3 = lerp(gradient3(h011, dx, dy1, dz1), gradient3(h111, dx1, dy1, dz1), u);
    const Floats4 value = lerp(lerp(x0, x1, v), lerp(x2, x3, v), w);
    std::array<float, 4> values;
    std::memcpy(values.data(), &value, sizeof(value));
    return values;
}

std::array<int, 8> GradientNoise::cornerHashes(int ix, int iy, int iz) const
{
    const int a = hash(ix) + iy, aa = hash(a) + iz, ab = hash(a + 1) + iz;
    const int b = hash(ix + 1) + iy, ba = hash(b) + iz, bb = hash(b + 1) + iz;
    return {hash(aa), hash(ba), hash(ab), hash(bb), hash(aa + 1), hash(ba + 1), hash(ab + 1), hash(bb + 1)};
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

std::array<NoiseSample, 4> GradientNoise::sample(const std::array<Vec3f, 4>& p) const
{
    Floats4 x, y, z;
    for (int lane = 0; lane < 4; ++lane) {
        x[lane] = p[lane][0];
        y[lane] = p[lane][1];
        z[lane] = p[lane][2];
    }
    Ints4 ix, iy, iz;
    const Floats4 dx = x - floor(x, ix), dy = y - floor(y, iy), dz = z - floor(z, iz);
    // The corners' gradients, lane by lane (no gather in SSE2).
    Floats4 g[8][3];
    for (int lane = 0; lane < 4; ++lane) {
        const std::array<int, 8> corners = cornerHashes(ix[lane], iy[lane], iz[lane]);
        for (int corner = 0; corner < 8; ++corner)
            for (int axis = 0; axis < 3; ++axis) g[corner][axis][lane] = kCubeEdges[corners[corner] & 15][axis];
    }
    Floats4 value, gradient[3];
    cellSample(g, dx, dy, dz, value, gradient);
    std::array<NoiseSample, 4> samples;
    for (int lane = 0; lane < 4; ++lane)
        samples[lane] = {value[lane], Vec3f(gradient[0][lane], gradient[1][lane], gradient[2][lane])};
    return samples;
}

float fbm(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options)
{
    const FbmQuery query{p, options};
    float value;
    fbm(noise, &query, 1, &value);
    return value;
}

void fbm(const GradientNoise& noise, const FbmQuery* queries, std::size_t count, float* values)
{
    fractalSums(noise, queries, count, values, fbmSum);
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
    const FbmQuery query{p, options};
    float value;
    billow(noise, &query, 1, &value);
    return value;
}

void billow(const GradientNoise& noise, const FbmQuery* queries, std::size_t count, float* values)
{
    fractalSums(noise, queries, count, values, billowSum);
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
