#include <vfield/volume/density_splat.h>

#include <vfield/core/error.h>

#include <openvdb/tools/Composite.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <cmath>

namespace vfield {

VolumeOptions volumeOptionsFromJson(const JsonValue& json)
{
    JsonObject o(json);
    VolumeOptions v;
    v.voxelSize = o.number("voxelSize", v.voxelSize, 0.0, 1e9);
    v.kernelRadius = o.number("kernelRadius", v.kernelRadius, 0.0, 1e9);
    v.densityPerParticle = o.number("densityPerParticle", v.densityPerParticle, 0.0, 1e12);
    o.finish();
    return v;
}

namespace {

/// Unnormalized density (sum of W) and momentum (sum of W v) of a range of particles.
struct Splat {
    openvdb::FloatGrid::Ptr weight;
    openvdb::Vec3SGrid::Ptr momentum;

    explicit Splat(const openvdb::math::Transform::Ptr& transform)
        : weight(openvdb::FloatGrid::create(0.0f)), momentum(openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f)))
    {
        weight->setTransform(transform);
        momentum->setTransform(transform);
    }
};

/// Particles per leaf of the fixed reduction tree: the order of float sums
/// depends on this constant only, not on the threads.
constexpr std::size_t kParticlesPerChunk = 16384;

} // namespace

DensityGrids splatParticles(const ParticleSet& particles, const VolumeOptions& options)
{
    double meanRadius = 0.0;
    for (const float r : particles.radius) meanRadius += r;
    meanRadius = particles.size() > 0 ? meanRadius / double(particles.size()) : 1.0;
    const double voxel = options.voxelSize > 0 ? options.voxelSize : meanRadius;
    const double radius = std::max(options.kernelRadius > 0 ? options.kernelRadius : 2.0 * meanRadius, voxel);
    if (radius / voxel > 32.0)
        throw ValueError("kernel radius " + std::to_string(radius) + " spans more than 32 voxels of " + std::to_string(voxel));
    const double norm = options.densityPerParticle * 315.0 / (64.0 * M_PI * radius * radius * radius);

    const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
    const int reach = int(std::ceil(radius / voxel));
    const double radiusSqr = radius * radius;

    const auto splatRange = [&](const tbb::blocked_range<std::size_t>& range, Splat& into) {
        auto weight = into.weight->getAccessor();
        auto momentum = into.momentum->getAccessor();
        for (std::size_t p = range.begin(); p != range.end(); ++p) {
            const Vec3d x(particles.position[p]);
            const openvdb::Vec3s v = particles.velocity[p];
            const openvdb::Vec3d index = transform->worldToIndex(x);
            const openvdb::Coord centre = openvdb::Coord::round(index);
            for (int i = -reach; i <= reach; ++i)
                for (int j = -reach; j <= reach; ++j)
                    for (int k = -reach; k <= reach; ++k) {
                        const openvdb::Coord c = centre.offsetBy(i, j, k);
                        const double r2 = (transform->indexToWorld(c) - x).lengthSqr();
                        if (r2 >= radiusSqr) continue;
                        const double q = 1.0 - r2 / radiusSqr;
                        const float w = float(q * q * q);
                        weight.modifyValue(c, [w](float& value) { value += w; });
                        momentum.modifyValue(c, [w, &v](openvdb::Vec3s& value) { value += v * w; });
                    }
        }
    };

    Splat total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, particles.size(), kParticlesPerChunk), Splat(transform),
        [&](const tbb::blocked_range<std::size_t>& range, const Splat&) {
            Splat partial(transform); // its own grids: the identity's are shared by every chunk
            splatRange(range, partial);
            return partial;
        },
        [](Splat a, const Splat& b) {
            openvdb::tools::compSum(*a.weight, *b.weight);
            openvdb::tools::compSum(*a.momentum, *b.momentum);
            return a;
        },
        tbb::simple_partitioner());

    DensityGrids grids;
    grids.density = openvdb::FloatGrid::create(0.0f);
    grids.density->setTransform(transform->copy());
    grids.density->setName("density");
    grids.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    grids.velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grids.velocity->setTransform(transform->copy());
    grids.velocity->setName("vel");
    grids.velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);

    auto density = grids.density->getAccessor();
    auto velocity = grids.velocity->getAccessor();
    auto momentum = total.momentum->getConstAccessor();
    for (auto it = total.weight->cbeginValueOn(); it; ++it) {
        const float w = *it;
        if (!(w > 0.0f)) continue;
        density.setValue(it.getCoord(), float(norm * w));
        velocity.setValue(it.getCoord(), momentum.getValue(it.getCoord()) / w);
    }
    return grids;
}

} // namespace vfield
