#include <vfield/sim/particles.h>

namespace vfield {

void ParticleSet::reserve(std::size_t n)
{
    position.reserve(n);
    velocity.reserve(n);
    rest.reserve(n);
    id.reserve(n);
    radius.reserve(n);
    cloud.reserve(n);
}

void ParticleSet::keep(const std::vector<uint8_t>& alive)
{
    std::size_t kept = 0;
    for (std::size_t i = 0; i < size(); ++i) {
        if (!alive[i]) continue;
        position[kept] = position[i];
        velocity[kept] = velocity[i];
        rest[kept] = rest[i];
        id[kept] = id[i];
        radius[kept] = radius[i];
        cloud[kept] = cloud[i];
        ++kept;
    }
    position.resize(kept);
    velocity.resize(kept);
    rest.resize(kept);
    id.resize(kept);
    radius.resize(kept);
    cloud.resize(kept);
}

} // namespace vfield
