#include <vfield/core/error.h>
#include <vfield/core/noise.h>
#include <vfield/image/silhouette.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace vfield;

namespace {

constexpr int kSize = 512;

template<typename Inside>
std::vector<uint8_t> maskOf(const Inside& inside)
{
    std::vector<uint8_t> mask(std::size_t(kSize) * kSize);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) mask[std::size_t(y) * kSize + std::size_t(x)] = inside(x, y) ? 1 : 0;
    return mask;
}

} // namespace

TEST_CASE("silhouette: a disk's outline measures 1, its area as covered", "[image]")
{
    const double radius = 150.0;
    const auto disk = maskOf([&](int x, int y) { return std::hypot(x + 0.5 - 256.0, y + 0.5 - 256.0) < radius; });
    const SilhouetteMeasure m = measureSilhouette(disk, kSize, kSize);
    INFO("dimension " << m.dimension);
    // Within the estimator's bias on a smooth curve: a disk 300 pixels
    // across holds few 64-pixel boxes (0.94 here).
    CHECK(m.dimension == Approx(1.0).margin(0.08));
    CHECK(m.coverage == Approx(M_PI * radius * radius / (kSize * kSize)).epsilon(0.01));
}

TEST_CASE("silhouette: isolines of fractional Brownian surfaces measure 2 - H, rougher for a larger gain", "[image]")
{
    // Octaves of gain g and lacunarity 2 make a surface of Hurst exponent
    // H = -log2(g); its isolines have dimension 2 - H (Mandelbrot), here
    // 1.26 and 1.42, which the estimator reads within its small-box bias.
    const GradientNoise noise(7);
    double previous = 1.0;
    for (const double gain : {0.6, 0.75}) {
        FractalOptions fractal;
        fractal.octaves = 9;
        fractal.gain = gain;
        const auto island = maskOf([&](int x, int y) { return fbm(noise, x / 160.0f, y / 160.0f, fractal) > 0.0f; });
        const SilhouetteMeasure m = measureSilhouette(island, kSize, kSize);
        const double expected = 2.0 + std::log2(gain);
        INFO("gain " << gain << ": dimension " << m.dimension << ", expected about " << expected);
        CHECK(m.dimension == Approx(expected).margin(0.1));
        CHECK(m.dimension > previous);
        previous = m.dimension;
    }
}

TEST_CASE("silhouette: box sizes that are not powers of two in order are refused", "[image]")
{
    const std::vector<uint8_t> empty(std::size_t(kSize) * kSize, 0);
    SilhouetteOptions options;
    options.smallestBox = 3;
    CHECK_THROWS_AS(measureSilhouette(empty, kSize, kSize, options), ValueError);
    options.smallestBox = 64;
    options.largestBox = 2;
    CHECK_THROWS_AS(measureSilhouette(empty, kSize, kSize, options), ValueError);
}
