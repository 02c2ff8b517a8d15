#include <vfield/sim/emission.h>

#include <vfield/core/noise.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace vfield {

namespace {

/// Uniform double in [0, 1) from a 64-bit generator (the standard's
/// distributions differ between libraries; this does not).
double unitRandom(std::mt19937_64& random) { return double(random() >> 11) * (1.0 / 9007199254740992.0); }

/// A point of the cloud's shape, uniform: rejection sampling from the box
/// around it. With billow the shape's surface is pulled in by up to that
/// fraction of its radii where the billow noise is high, so the cloud is
/// lumps with creases between (every point within 1 - billow of the centre is
/// kept, so the loop ends).
Vec3d samplePointIn(const CloudSettings& cloud, const GradientNoise& noise, std::mt19937_64& random)
{
    const double billowSize =
        cloud.billowSize > 0.0 ? cloud.billowSize : std::min({cloud.radii[0], cloud.radii[1], cloud.radii[2]}) / 3.0;
    for (;;) {
        const Vec3d u(2 * unitRandom(random) - 1, 2 * unitRandom(random) - 1, 2 * unitRandom(random) - 1);
        const Vec3d offset(u[0] * cloud.radii[0], u[1] * cloud.radii[1], u[2] * cloud.radii[2]);
        // The shape's norm: 1 on its surface.
        const double r =
            cloud.shape == CloudSettings::Shape::Box ? std::max({std::abs(u[0]), std::abs(u[1]), std::abs(u[2])}) : u.length();
        if (r > 1.0) continue;
        if (cloud.billow > 0.0 && r > 1.0 - cloud.billow * double(billow(noise, Vec3f(offset / billowSize), {3, 2.0, 0.5})))
            continue;
        return cloud.center + offset;
    }
}

} // namespace

ParticleSet emitClouds(const SimulationSettings& setup)
{
    int64_t total = 0;
    for (const CloudSettings& c : setup.clouds) total += c.count;
    ParticleSet particles;
    particles.reserve(std::size_t(total));
    uint32_t nextId = 0;
    for (std::size_t c = 0; c < setup.clouds.size(); ++c) {
        const CloudSettings& cloud = setup.clouds[c];
        std::mt19937_64 random(setup.seed * 0x9e3779b97f4a7c15ull ^ (cloud.seed + 0x632be59bd9b4e019ull * (c + 1)));
        const GradientNoise puffs(cloud.seed);
        for (int64_t k = 0; k < cloud.count; ++k) {
            particles.position.emplace_back(samplePointIn(cloud, puffs, random));
            particles.velocity.emplace_back(cloud.velocity);
            particles.rest.push_back(particles.position.back());
            particles.peak.push_back(particles.position.back().y());
            particles.id.push_back(nextId++);
            particles.radius.push_back(float(cloud.particleRadius));
            particles.cloud.push_back(uint16_t(c));
        }
    }
    return particles;
}

} // namespace vfield
