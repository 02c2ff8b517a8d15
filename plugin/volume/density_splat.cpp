#include <vfield/volume/density_splat.h>

#include <vfield/core/error.h>

#include <openvdb/tools/Composite.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
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

    // Particles in the order of the OpenVDB leaf (8^3 voxels) they fall in, a
    // stable sort so the order, and with it every float sum, is fixed: each
    // chunk then touches few leaves and its accessors stay on them.
    std::vector<uint32_t> order(particles.size());
    {
        std::vector<uint64_t> leafKey(particles.size());
        for (std::size_t p = 0; p < particles.size(); ++p) {
            const openvdb::Coord c = openvdb::Coord::round(transform->worldToIndex(Vec3d(particles.position[p]))) >> 3;
            // 21 bits per axis, offset so negative coordinates sort too.
            leafKey[p] = (uint64_t(c.x() + (1 << 20)) << 42) | (uint64_t(c.y() + (1 << 20)) << 21) | uint64_t(c.z() + (1 << 20));
            order[p] = uint32_t(p);
        }
        std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return leafKey[a] < leafKey[b]; });
    }

    const double reachSqr = radiusSqr / (voxel * voxel); // the kernel radius squared, in voxels
    const auto splatRange = [&](const tbb::blocked_range<std::size_t>& range, Splat& into) {
        auto weight = into.weight->getAccessor();
        auto momentum = into.momentum->getAccessor();
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
            const std::size_t p = order[n];
            const openvdb::Vec3s v = particles.velocity[p];
            const openvdb::Vec3d index = transform->worldToIndex(Vec3d(particles.position[p]));
            const openvdb::Coord centre = openvdb::Coord::round(index);
            for (int i = -reach; i <= reach; ++i)
                for (int j = -reach; j <= reach; ++j)
                    for (int k = -reach; k <= reach; ++k) {
                        const openvdb::Coord c = centre.offsetBy(i, j, k);
                        const double r2 = (c.asVec3d() - index).lengthSqr(); // in voxels: the transform is uniform
                        if (r2 >= reachSqr) continue;
                        const double q = 1.0 - r2 / reachSqr;
                        const float w = float(q * q * q);
                        auto* weightLeaf = weight.touchLeaf(c);
                        auto* momentumLeaf = momentum.touchLeaf(c);
                        const openvdb::Index offset = weightLeaf->coordToOffset(c);
                        weightLeaf->setValueOn(offset, weightLeaf->getValue(offset) + w);
                        momentumLeaf->setValueOn(offset, momentumLeaf->getValue(offset) + v * w);
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
