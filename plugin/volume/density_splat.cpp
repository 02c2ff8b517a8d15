#include <vfield/volume/density_splat.h>

#include <vfield/core/options.h>

#include <openvdb/tools/Composite.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace vfield {

void VolumeOptions::validate() const
{
    requireNumber("voxelSize", voxelSize, 0.0, 1e9);
    requireNumber("kernelRadius", kernelRadius, 0.0, 1e9);
    requireNumber("densityPerParticle", densityPerParticle, 0.0, 1e12);
    if (voxelSize > 0.0 && kernelRadius > 0.0)
        require(kernelRadius / voxelSize <= kMaxKernelVoxels, "kernelRadius",
                "kernel radius " + numberText(kernelRadius) + " spans more than " + numberText(kMaxKernelVoxels) + " voxels of " +
                    numberText(voxelSize));
}

VolumeOptions VolumeOptions::resolved(double meanParticleRadius) const
{
    VolumeOptions r = *this;
    if (r.voxelSize == 0.0) r.voxelSize = meanParticleRadius;
    r.kernelRadius = std::max(r.kernelRadius > 0.0 ? r.kernelRadius : 2.0 * meanParticleRadius, r.voxelSize);
    return r;
}

VolumeOptions volumeOptionsFromJson(const JsonValue& json)
{
    return readOptions<VolumeOptions>(json, [&](JsonObject& o, VolumeOptions& v) {
        v.voxelSize = o.number("voxelSize", v.voxelSize);
        v.kernelRadius = o.number("kernelRadius", v.kernelRadius);
        v.densityPerParticle = o.number("densityPerParticle", v.densityPerParticle);
    });
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
/// The most voxels a chunk splats densely at once (64 MiB of weights and momenta).
constexpr std::size_t kMaxDenseVoxels = std::size_t(1) << 22;

} // namespace

DensityGrids splatParticles(const ParticleSet& particles, const VolumeOptions& options)
{
    double meanRadius = 0.0;
    for (const float r : particles.radius) meanRadius += r;
    meanRadius = particles.size() > 0 ? meanRadius / double(particles.size()) : 1.0;
    const VolumeOptions resolved = options.resolved(meanRadius);
    resolved.validate();
    const double voxel = resolved.voxelSize, radius = resolved.kernelRadius;
    const double norm = resolved.densityPerParticle * 315.0 / (64.0 * M_PI * radius * radius * radius);

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
    // A chunk's particles are splatted into dense arrays over their box, then
    // the voxels they reached are added to the chunk's grids: the inner loop
    // is plain arithmetic, with no tree lookups. Each voxel's sum still runs
    // over the particles in order, so the sums are those of voxel-by-voxel
    // accumulation. A chunk whose box is too large is halved, in order.
    const std::function<void(std::size_t, std::size_t, Splat&)> splatRange = [&](std::size_t first, std::size_t last,
                                                                                 Splat& into) {
        openvdb::CoordBBox box;
        for (std::size_t n = first; n != last; ++n)
            box.expand(openvdb::Coord::round(transform->worldToIndex(Vec3d(particles.position[order[n]]))));
        box.expand(reach);
        const openvdb::Coord dim = box.dim();
        const std::size_t voxels = std::size_t(dim.x()) * std::size_t(dim.y()) * std::size_t(dim.z());
        if (voxels > kMaxDenseVoxels && last - first > 1) {
            const std::size_t middle = first + (last - first) / 2;
            splatRange(first, middle, into);
            splatRange(middle, last, into);
            return;
        }
        std::vector<float> weight(voxels, 0.0f);
        std::vector<openvdb::Vec3s> momentum(voxels, openvdb::Vec3s(0.0f));
        const openvdb::Coord origin = box.min();
        for (std::size_t n = first; n != last; ++n) {
            const std::size_t p = order[n];
            const openvdb::Vec3s v = particles.velocity[p];
            const openvdb::Vec3d index = transform->worldToIndex(Vec3d(particles.position[p]));
            const openvdb::Coord centre = openvdb::Coord::round(index);
            // The kernel's sphere row by row along z (z is fastest in the
            // arrays, as in OpenVDB leaves); one voxel of slack at each end of
            // a row, the exact test decides.
            for (int i = -reach; i <= reach; ++i) {
                const int x = centre.x() + i;
                const double dx = double(x) - index.x(), dx2 = dx * dx;
                if (dx2 >= reachSqr) continue;
                for (int j = -reach; j <= reach; ++j) {
                    const int y = centre.y() + j;
                    const double dy = double(y) - index.y(), dxy2 = dx2 + dy * dy;
                    if (dxy2 >= reachSqr) continue;
                    const double halfRow = std::sqrt(reachSqr - dxy2);
                    const int zFirst = std::max(centre.z() - reach, int(std::floor(index.z() - halfRow)));
                    const int zLast = std::min(centre.z() + reach, int(std::ceil(index.z() + halfRow)));
                    const std::size_t row = (std::size_t(x - origin.x()) * dim.y() + std::size_t(y - origin.y())) * dim.z();
                    for (int z = zFirst; z <= zLast; ++z) {
                        const double dz = double(z) - index.z();
                        const double r2 = dxy2 + dz * dz;
                        if (r2 >= reachSqr) continue;
                        const double q = 1.0 - r2 / reachSqr;
                        const float w = float(q * q * q);
                        const std::size_t at = row + std::size_t(z - origin.z());
                        weight[at] += w;
                        momentum[at] += v * w;
                    }
                }
            }
        }
        auto weightAccessor = into.weight->getAccessor();
        auto momentumAccessor = into.momentum->getAccessor();
        for (int x = 0; x < dim.x(); ++x)
            for (int y = 0; y < dim.y(); ++y)
                for (int z = 0; z < dim.z(); ++z) {
                    const std::size_t at = (std::size_t(x) * dim.y() + std::size_t(y)) * dim.z() + std::size_t(z);
                    if (weight[at] == 0.0f) continue;
                    const openvdb::Coord c = origin.offsetBy(x, y, z);
                    weightAccessor.setValueOn(c, weightAccessor.getValue(c) + weight[at]);
                    momentumAccessor.setValueOn(c, momentumAccessor.getValue(c) + momentum[at]);
                }
    };

    Splat total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, particles.size(), kParticlesPerChunk), Splat(transform),
        [&](const tbb::blocked_range<std::size_t>& range, const Splat&) {
            Splat partial(transform); // its own grids: the identity's are shared by every chunk
            splatRange(range.begin(), range.end(), partial);
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
