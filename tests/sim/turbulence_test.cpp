// Turbulence: curl noise without divergence, as strong as asked, sliding as
// asked, and what it stirs stays out of the meshes on any thread count.

#include <vfield/scene/scene.h>
#include <vfield/sim/clearance.h>
#include <vfield/sim/simulator.h>
#include <vfield/sim/turbulence.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <vector>

using namespace vfield;

namespace {

std::vector<Vec3d> randomPoints(std::size_t count, double extent)
{
    std::mt19937_64 random(17);
    std::uniform_real_distribution<double> coordinate(-extent, extent);
    std::vector<Vec3d> points;
    for (std::size_t i = 0; i < count; ++i) points.emplace_back(coordinate(random), coordinate(random), coordinate(random));
    return points;
}

/// The mean over points of |div f| and of |d f_x/dx| + |d f_y/dy| + |d f_z/dz|
/// (the divergence's terms, which a field with sources leaves unbalanced),
/// by central differences of step h.
template<typename Field>
std::pair<double, double> meanDivergenceAndTerms(const Field& f, const std::vector<Vec3d>& points, double h)
{
    double divergence = 0.0, terms = 0.0;
    for (const Vec3d& p : points) {
        double sum = 0.0, magnitudes = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            Vec3d step(0.0);
            step[axis] = h;
            const double partial = (f(p + step)[axis] - f(p - step)[axis]) / (2.0 * h);
            sum += partial;
            magnitudes += std::abs(partial);
        }
        divergence += std::abs(sum);
        terms += magnitudes;
    }
    return {divergence / double(points.size()), terms / double(points.size())};
}

} // namespace

TEST_CASE("turbulence: its acceleration has no divergence, where a noise's gradient has plenty", "[sim]")
{
    TurbulenceSettings spec;
    spec.strength = 5.0;
    spec.size = 8.0;
    spec.octaves = 4;
    const Turbulence turbulence(spec, 1, 24.0);
    const std::vector<Vec3d> points = randomPoints(2000, 100.0);
    // A step of a fiftieth of the finest swirls' size: small against their
    // curvature, large against the noise's float rounding.
    const double h = spec.size / 8.0 / 50.0;
    const auto [divergence, terms] =
        meanDivergenceAndTerms([&](const Vec3d& p) { return turbulence.acceleration(p, 1.5); }, points, h);
    CHECK(terms > 1.0);
    CHECK(divergence < 0.01 * terms);

    // The same measure fails a field with sources: one noise's gradient.
    const GradientNoise noise(3);
    const auto [gradientDivergence, gradientTerms] =
        meanDivergenceAndTerms([&](const Vec3d& p) { return Vec3d(noise.sample(Vec3f(p / spec.size)).gradient); }, points, h);
    CHECK(gradientDivergence > 0.3 * gradientTerms);
}

TEST_CASE("turbulence: its root mean square is its strength, whatever the octaves and roughness", "[sim]")
{
    const std::vector<Vec3d> points = randomPoints(20000, 500.0);
    for (const auto& [octaves, roughness] : {std::pair{1, 0.5}, std::pair{3, 0.5}, std::pair{6, 0.8}}) {
        TurbulenceSettings spec;
        spec.strength = 3.0;
        spec.size = 10.0;
        spec.octaves = octaves;
        spec.roughness = roughness;
        const Turbulence turbulence(spec, 1, 24.0);
        double meanSquare = 0.0;
        for (const Vec3d& p : points) meanSquare += turbulence.acceleration(p, 0.0).lengthSqr();
        INFO(octaves << " octaves, roughness " << roughness);
        CHECK(std::sqrt(meanSquare / double(points.size())) == Approx(3.0).epsilon(0.05));
    }
}

TEST_CASE("turbulence: a point reads the same every time; the swirls slide down by evolution x size a second", "[sim]")
{
    TurbulenceSettings spec;
    spec.strength = 2.0;
    spec.size = 10.0;
    spec.octaves = 1;
    spec.evolution = 0.3;
    const Turbulence turbulence(spec, 1, 24.0);
    for (const Vec3d& p : randomPoints(100, 50.0)) {
        CHECK(turbulence.acceleration(p, 2.0) == turbulence.acceleration(p, 2.0));
        // After 2 s the pattern has slid 0.3 x 10 x 2 = 6 units down.
        const Vec3d later = turbulence.acceleration(p - Vec3d(0, 6, 0), 2.0), before = turbulence.acceleration(p, 0.0);
        CHECK((later - before).length() < 1e-4 * spec.strength);
    }
    TurbulenceSettings other = spec;
    other.seed = 2;
    const Vec3d p(1.3, 2.7, -4.1);
    CHECK((Turbulence(other, 1, 24.0).acceleration(p, 0.0) - turbulence.acceleration(p, 0.0)).length() > 0.1);
}

TEST_CASE("turbulence: keyed strength and size are read at the time asked", "[sim]")
{
    TurbulenceSettings keyed;
    keyed.strength = 3.0;
    keyed.size = 10.0;
    // Frame f is at (f - 1) / 24 s: strength 0 at frame 1, 3 at frame 25; size 10, then 20 from frame 25 on.
    keyed.animation.set("strength", KeyTrack({1.0, 25.0}, {0.0, 3.0}, 1, Interpolation::Linear, false));
    keyed.animation.set("size", KeyTrack({1.0, 25.0}, {10.0, 20.0}, 1, Interpolation::Step, false));
    TurbulenceSettings constant = keyed;
    constant.animation = Animation();
    TurbulenceSettings larger = constant;
    larger.size = 20.0;
    const Turbulence turbulence(keyed, 1, 24.0), atKeyOne(constant, 1, 24.0), atKeyTwo(larger, 1, 24.0);
    for (const Vec3d& p : randomPoints(50, 50.0)) {
        CHECK(turbulence.acceleration(p, 0.0) == Vec3d(0.0));
        CHECK(turbulence.acceleration(p, 0.5) == atKeyOne.acceleration(p, 0.5) * 0.5);
        CHECK(turbulence.acceleration(p, 1.0) == atKeyTwo.acceleration(p, 1.0));
    }
}

TEST_CASE("simulator: turbulence stirs a cloud the same on any thread count, none of it into the ground", "[sim]")
{
    // Strong swirls (60 units/s^2 against gravity's 9.81) drive particles
    // into a slab below them: the slab's field and contact keep them out.
    // Before contact stopped paths that would end deeper than the slab's
    // level set reaches inside, up to 7 of the 3,000 ended inside it.
    const std::string text = R"({"version": 1, "frames": {"start": 1, "end": 30, "fps": 24}, "seed": 1,
      "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -6, -20], "max": [20, -2, 20]}},
                   "repulsion": {"margin": 4, "maxPerLeaf": 2, "maxLevel": 5}}],
      "clouds": [{"name": "puff", "count": 3000, "center": [0, 2, 0], "radius": 4, "drag": 0.5}],
      "fields": [{"acceleration": [0, -9.81, 0]}],
      "turbulence": [{"strength": 60, "size": 6, "octaves": 3, "evolution": 0.5}],
      "simulation": {"domain": {"min": [-40, -40, -40], "max": [40, 40, 40]}}})";
    const Scene scene = parseScene(text, "stirred.json");
    const auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        Simulator sim(scene.simulation);
        const ClearanceProbe probe(sim);
        uint64_t penetrations = 0;
        for (int frame = 2; frame <= 30; ++frame) {
            sim.advanceFrame();
            penetrations += probe.measureParticles().penetrations;
        }
        CHECK(penetrations == 0);
        return sim.particles().position;
    };
    const std::vector<Vec3f> one = run(1), two = run(2);
    CHECK(one == two);

    // Without the swirls the puff falls as one; with them its particles part.
    const auto spread = [](const std::vector<Vec3f>& points) {
        Vec3d centroid(0.0);
        for (const Vec3f& p : points) centroid += Vec3d(p);
        centroid /= double(points.size());
        double meanSquare = 0.0;
        for (const Vec3f& p : points) meanSquare += (Vec3d(p) - centroid).lengthSqr();
        return std::sqrt(meanSquare / double(points.size()));
    };
    Scene calm = scene;
    calm.simulation.turbulence.clear();
    Simulator still(calm.simulation);
    for (int frame = 2; frame <= 30; ++frame) still.advanceFrame();
    INFO("spread calm " << spread(still.particles().position) << ", stirred " << spread(one));
    CHECK(spread(one) > 1.2 * spread(still.particles().position));
}
