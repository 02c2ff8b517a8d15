#include <vfield/core/noise.h>

#include <catch2/catch.hpp>

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
