#include <vfield/core/noise.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>

using namespace vfield;

namespace {

/// Central differences of f at p, in double, over a step small against the
/// finest octave's period and large against float rounding at p.
template<typename F>
Vec3d centralDifferences(const F& f, const Vec3f& p, float step)
{
    Vec3d gradient;
    for (int axis = 0; axis < 3; ++axis) {
        Vec3f plus = p, minus = p;
        plus[axis] += step;
        minus[axis] -= step;
        gradient[axis] = (double(f(plus)) - double(f(minus))) / double(plus[axis] - minus[axis]);
    }
    return gradient;
}

} // namespace

TEST_CASE("noise: a sample's value is the noise and its gradient the noise's derivative", "[noise]")
{
    const GradientNoise noise(42);
    std::mt19937 random(5);
    std::uniform_real_distribution<float> coordinate(-40.0f, 40.0f);
    double worstValue = 0.0, worstGradient = 0.0, largestGradient = 0.0;
    for (int n = 0; n < 2000; ++n) {
        const Vec3f p(coordinate(random), coordinate(random), coordinate(random));
        const NoiseSample s = noise.sample(p);
        worstValue = std::max(worstValue, std::abs(double(s.value) - double(noise(p[0], p[1], p[2]))));
        const Vec3d expected = centralDifferences([&](const Vec3f& q) { return noise(q[0], q[1], q[2]); }, p, 1e-2f);
        worstGradient = std::max(worstGradient, (Vec3d(s.gradient) - expected).length());
        largestGradient = std::max(largestGradient, expected.length());
    }
    INFO("worst value error " << worstValue << ", worst gradient error " << worstGradient << " of gradients up to "
                              << largestGradient);
    CHECK(worstValue < 1e-5);
    CHECK(largestGradient > 1.0); // the gradients compared are not all near zero
    CHECK(worstGradient < 2e-3 * largestGradient);
}

TEST_CASE("noise: fBm's sampled gradient is the derivative of fBm over every octave", "[noise]")
{
    const GradientNoise noise(7);
    const FractalOptions options{4, 2.0, 0.5};
    std::mt19937 random(11);
    std::uniform_real_distribution<float> coordinate(-10.0f, 10.0f);
    double worstValue = 0.0, worstGradient = 0.0, largestGradient = 0.0;
    for (int n = 0; n < 2000; ++n) {
        const Vec3f p(coordinate(random), coordinate(random), coordinate(random));
        const NoiseSample s = fbmSample(noise, p, options);
        worstValue = std::max(worstValue, std::abs(double(s.value) - double(fbm(noise, p, options))));
        const Vec3d expected = centralDifferences([&](const Vec3f& q) { return fbm(noise, q, options); }, p, 1e-3f);
        worstGradient = std::max(worstGradient, (Vec3d(s.gradient) - expected).length());
        largestGradient = std::max(largestGradient, expected.length());
    }
    INFO("worst value error " << worstValue << ", worst gradient error " << worstGradient << " of gradients up to "
                              << largestGradient);
    CHECK(worstValue < 1e-5);
    CHECK(worstGradient < 2e-3 * largestGradient);
}

TEST_CASE("noise: billow is |noise| summed over octaves, lumps in [0, 1] with creases at the noise's zeros", "[noise]")
{
    const GradientNoise noise(5);
    std::mt19937 random(2);
    std::uniform_real_distribution<float> coordinate(-50.0f, 50.0f);
    double sum = 0.0, lowest = 1.0, highest = 0.0;
    const int count = 4000;
    for (int i = 0; i < count; ++i) {
        const Vec3f p(coordinate(random), coordinate(random), coordinate(random));
        // One octave: twice the noise's magnitude, zero where it crosses zero.
        CHECK(billow(noise, p, {1, 2.0, 0.5}) == Approx(std::min(1.0f, 2.0f * std::abs(noise(p[0], p[1], p[2])))).margin(1e-6));
        const float b = billow(noise, p, {3, 2.0, 0.5});
        REQUIRE(b >= 0.0f);
        REQUIRE(b <= 1.0f);
        sum += b;
        lowest = std::min(lowest, double(b));
        highest = std::max(highest, double(b));
    }
    // Spread over the range, not a constant: puffs and creases both occur.
    CHECK(sum / count > 0.2);
    CHECK(sum / count < 0.7);
    CHECK(lowest < 0.1);
    CHECK(highest > 0.8);
}

namespace {

/// fBm (or billow, |noise| an octave) as a loop over the scalar noise,
/// octave by octave: what the batched evaluation must reproduce.
float octaveByOctave(const GradientNoise& noise, const Vec3f& p, const FractalOptions& options, bool billowed)
{
    float sum = 0.0f, amplitude = 1.0f, total = 0.0f, frequency = 1.0f;
    for (int octave = 0; octave < options.octaves; ++octave) {
        const float shift = 17.31f * float(octave);
        const float n = noise(p[0] * frequency + shift, p[1] * frequency - shift, p[2] * frequency + 0.5f * shift);
        sum += amplitude * (billowed ? std::abs(n) : n);
        total += amplitude;
        amplitude *= float(options.gain);
        frequency *= float(options.lacunarity);
    }
    return billowed ? std::min(1.0f, 2.0f * sum / total) : sum / total;
}

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

} // namespace

TEST_CASE("noise: four values at once are the scalar noise's bit for bit, on lattice planes and below zero too", "[noise]")
{
    const GradientNoise noise(20171);
    std::mt19937 random(3);
    std::uniform_real_distribution<float> coordinate(-300.0f, 300.0f);
    int differing = 0;
    for (int n = 0; n < 20000; ++n) {
        std::array<float, 4> x, y, z;
        for (int lane = 0; lane < 4; ++lane) {
            x[lane] = coordinate(random);
            y[lane] = coordinate(random);
            z[lane] = coordinate(random);
        }
        if (n % 4 == 0) x[0] = std::round(x[0]); // on a lattice plane: a zero there
        if (n % 8 == 0) y[1] = -std::round(std::abs(y[1]));
        const std::array<float, 4> lanes = noise(x, y, z);
        for (int lane = 0; lane < 4; ++lane) differing += !sameBits(lanes[lane], noise(x[lane], y[lane], z[lane]));
    }
    CHECK(differing == 0);
}

TEST_CASE("noise: four samples at once are the scalar samples bit for bit, value and gradient", "[noise]")
{
    const GradientNoise noise(977);
    std::mt19937 random(8);
    std::uniform_real_distribution<float> coordinate(-300.0f, 300.0f);
    int differing = 0;
    for (int n = 0; n < 20000; ++n) {
        std::array<Vec3f, 4> points;
        for (Vec3f& p : points) p = Vec3f(coordinate(random), coordinate(random), coordinate(random));
        if (n % 4 == 0) points[2][1] = std::round(points[2][1]); // on a lattice plane
        const std::array<NoiseSample, 4> lanes = noise.sample(points);
        for (int lane = 0; lane < 4; ++lane) {
            const NoiseSample one = noise.sample(points[lane]);
            bool same = sameBits(lanes[lane].value, one.value);
            for (int axis = 0; axis < 3; ++axis) same = same && sameBits(lanes[lane].gradient[axis], one.gradient[axis]);
            differing += !same;
        }
    }
    CHECK(differing == 0);
}

TEST_CASE("noise: fBm and billow, alone or batched, are their octaves summed one by one, bit for bit", "[noise]")
{
    const GradientNoise noise(11);
    std::mt19937 random(4);
    std::uniform_real_distribution<float> coordinate(-60.0f, 60.0f);
    int differing = 0;
    for (int n = 0; n < 2000; ++n) {
        FbmQuery queries[4];
        for (int q = 0; q < 4; ++q)
            queries[q] = {Vec3f(coordinate(random), coordinate(random), coordinate(random)),
                          FractalOptions{1 + (n + 3 * q) % 16, 2.0, 0.5 + 0.1 * q}};
        float batched[4], batchedBillows[4];
        fbm(noise, queries, 4, batched);
        billow(noise, queries, 4, batchedBillows);
        for (const FbmQuery& query : queries) {
            const float expected = octaveByOctave(noise, query.point, query.options, false);
            differing += !sameBits(fbm(noise, query.point, query.options), expected);
            differing += !sameBits(batched[&query - queries], expected);
            const float expectedBillow = octaveByOctave(noise, query.point, query.options, true);
            differing += !sameBits(billow(noise, query.point, query.options), expectedBillow);
            differing += !sameBits(batchedBillows[&query - queries], expectedBillow);
        }
    }
    CHECK(differing == 0);
    const FbmQuery tooMany[5] = {{Vec3f(0.0f), {16, 2.0, 0.5}},
                                 {Vec3f(0.0f), {16, 2.0, 0.5}},
                                 {Vec3f(0.0f), {16, 2.0, 0.5}},
                                 {Vec3f(0.0f), {16, 2.0, 0.5}},
                                 {Vec3f(0.0f), {1, 2.0, 0.5}}};
    float values[5];
    CHECK_THROWS_WITH(fbm(noise, tooMany, 5, values), Catch::Contains("64 at once"));
    CHECK_THROWS_WITH(billow(noise, tooMany, 5, values), Catch::Contains("64 at once"));
    CHECK_THROWS_WITH(fbm(noise, Vec3f(0.0f), {17, 2.0, 0.5}), Catch::Contains("more than 16 octaves"));
}
