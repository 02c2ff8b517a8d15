#include <vfield/volume/density_splat.h>

#include <vfield/core/noise.h>
#include <vfield/core/options.h>

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

namespace vfield {

void VolumeDetail::validate() const
{
    requireNumber("voxelSize", voxelSize, 0.0, 1e9);
    requireNumber("frequency", frequency, 1e-9, 1e9);
    requireInteger("octaves", octaves, 1, 10);
    requireNumber("amplitude", amplitude, 0.0, 4.0);
    requireNumber("edgeSoftness", edgeSoftness, 0.0, 1e12);
}

void VolumeOptions::validate() const
{
    requireNumber("voxelSize", voxelSize, 0.0, 1e9);
    requireNumber("kernelRadius", kernelRadius, 0.0, 1e9);
    requireNumber("densityPerParticle", densityPerParticle, 0.0, 1e12);
    if (voxelSize > 0.0 && kernelRadius > 0.0)
        require(kernelRadius / voxelSize <= kMaxKernelVoxels, "kernelRadius",
                "kernel radius " + numberText(kernelRadius) + " spans more than " + numberText(kMaxKernelVoxels) + " voxels of " +
                    numberText(voxelSize));
    validatePart("detail", detail);
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
        if (const auto detail = o.find("detail"))
            v.detail = readOptions<VolumeDetail>(*detail, [](JsonObject& d, VolumeDetail& x) {
                x.voxelSize = d.number("voxelSize", x.voxelSize);
                x.frequency = d.number("frequency", x.frequency);
                x.octaves = d.integer("octaves", x.octaves);
                x.amplitude = d.number("amplitude", x.amplitude);
                x.edgeSoftness = d.number("edgeSoftness", x.edgeSoftness);
                x.seed = d.unsignedInteger("seed", x.seed);
            });
    });
}

namespace {

/// Unnormalized sums over a range of particles: of the kernel weights W, and
/// of W v and W rest, whose ratios to the weights are the mean velocity and
/// rest position.
struct Splat {
    openvdb::FloatGrid::Ptr weight;
    openvdb::Vec3SGrid::Ptr momentum, rest;

    explicit Splat(const openvdb::math::Transform::Ptr& transform)
        : weight(openvdb::FloatGrid::create(0.0f)), momentum(openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f))),
          rest(openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f)))
    {
        weight->setTransform(transform);
        momentum->setTransform(transform);
        rest->setTransform(transform);
    }
};

/// Particles per leaf of the fixed reduction tree: the order of float sums
/// depends on this constant only, not on the threads.
constexpr std::size_t kParticlesPerChunk = 16384;

/// Dense sums over a box around one leaf's particles, one array per
/// component so that the innermost loop (along z) is plain arithmetic.
struct DenseSums {
    openvdb::Coord origin, dim;
    std::vector<float> w, vx, vy, vz, rx, ry, rz;

    /// Zeroes the sums over a new box, keeping the arrays' memory.
    void reset(const openvdb::CoordBBox& box)
    {
        origin = box.min();
        dim = box.dim();
        const std::size_t n = std::size_t(dim.x()) * std::size_t(dim.y()) * std::size_t(dim.z());
        for (std::vector<float>* a : {&w, &vx, &vy, &vz, &rx, &ry, &rz}) a->assign(n, 0.0f);
    }
    std::size_t row(int x, int y) const
    {
        return (std::size_t(x - origin.x()) * std::size_t(dim.y()) + std::size_t(y - origin.y())) * std::size_t(dim.z());
    }
};

double smoothstep01(double x)
{
    const double t = std::clamp(x, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

/// The density resampled on a grid `ratio` times finer and shaped by noise at
/// the interpolated rest position. Each fine voxel is computed on its own, so
/// the grid is the same for any thread count.
openvdb::FloatGrid::Ptr detailedDensity(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid& rest,
                                        const VolumeDetail& detail, double edgeSoftness)
{
    const double coarse = density.voxelSize()[0];
    const int ratio = std::max(1, int(std::lround(coarse / detail.voxelSize)));
    const double fine = coarse / ratio;
    // Fine voxel ratio c + k (k = 0..ratio-1) lies inside coarse voxel c,
    // its centre at c + (k - (ratio - 1) / 2) / ratio coarse voxels.
    auto transform = openvdb::math::Transform::createLinearTransform(fine);
    transform->postTranslate(openvdb::Vec3d(-0.5 * (ratio - 1) * fine));

    // Every coarse voxel that trilinear reads can give density: the active ones and their neighbours.
    openvdb::MaskGrid mask(false);
    mask.topologyUnion(density);
    openvdb::tools::dilateActiveValues(mask.tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    std::vector<const openvdb::MaskTree::LeafNodeType*> coarseLeaves;
    for (auto leaf = mask.tree().cbeginLeaf(); leaf; ++leaf) coarseLeaves.push_back(leaf.getLeaf());

    const GradientNoise noise(detail.seed);
    const FractalOptions fractal{detail.octaves, 2.0, 0.5};
    const float frequency = float(detail.frequency), amplitude = float(detail.amplitude);
    const double inverseSoftness = 1.0 / edgeSoftness;
    using FineLeaf = openvdb::FloatTree::LeafNodeType;
    std::vector<std::vector<std::unique_ptr<FineLeaf>>> fineLeaves(coarseLeaves.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, coarseLeaves.size()), [&](const tbb::blocked_range<std::size_t>& range) {
        openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> densityAt(
            density.getConstAccessor(), density.transform());
        openvdb::tools::GridSampler<openvdb::Vec3SGrid::ConstAccessor, openvdb::tools::BoxSampler> restAt(rest.getConstAccessor(),
                                                                                                          rest.transform());
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
            std::map<openvdb::Coord, std::unique_ptr<FineLeaf>> leaves; // ordered: added to the tree in a fixed order
            for (auto voxel = coarseLeaves[n]->cbeginValueOn(); voxel; ++voxel) {
                const openvdb::Coord c = voxel.getCoord();
                for (int i = 0; i < ratio; ++i)
                    for (int j = 0; j < ratio; ++j)
                        for (int k = 0; k < ratio; ++k) {
                            const openvdb::Coord f(ratio * c.x() + i, ratio * c.y() + j, ratio * c.z() + k);
                            const openvdb::Vec3d p = transform->indexToWorld(f);
                            const double rho = densityAt.wsSample(p);
                            if (!(rho > 0.0)) continue;
                            const float g = fbm(noise, openvdb::Vec3f(restAt.wsSample(p)) * frequency, fractal);
                            // The noise scales the edge threshold rather than offsetting it, so a
                            // thin fringe is always eroded: no shell of faint density around the cloud.
                            const double shaped = rho * std::max(0.0, 1.0 + 0.5 * double(amplitude * g)) *
                                                  smoothstep01(rho * inverseSoftness * (1.0 + double(amplitude * g)));
                            if (!(shaped > 0.0)) continue;
                            std::unique_ptr<FineLeaf>& leaf = leaves[f & ~int32_t(FineLeaf::DIM - 1)];
                            if (!leaf) leaf = std::make_unique<FineLeaf>(f, 0.0f, false);
                            leaf->setValueOn(f, float(shaped));
                        }
            }
            for (auto& [origin, leaf] : leaves) fineLeaves[n].push_back(std::move(leaf));
        }
    });
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(transform);
    for (auto& leaves : fineLeaves)
        for (auto& leaf : leaves) grid->tree().addLeaf(leaf.release());
    return grid;
}

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
    const std::vector<Vec3f>& rest = particles.rest.size() == particles.size() ? particles.rest : particles.position;

    const auto transform = openvdb::math::Transform::createLinearTransform(voxel);
    const int reach = int(std::ceil(radius / voxel));

    // Particles in the order of the OpenVDB leaf (8^3 voxels) they fall in, a
    // stable sort so the order, and with it every float sum, is fixed: each
    // chunk then touches few leaves and its accessors stay on them.
    std::vector<uint32_t> order(particles.size());
    std::vector<uint64_t> leafKey(particles.size());
    for (std::size_t p = 0; p < particles.size(); ++p) {
        const openvdb::Coord c = openvdb::Coord::round(transform->worldToIndex(Vec3d(particles.position[p]))) >> 3;
        // 21 bits per axis, offset so negative coordinates sort too.
        leafKey[p] = (uint64_t(c.x() + (1 << 20)) << 42) | (uint64_t(c.y() + (1 << 20)) << 21) | uint64_t(c.z() + (1 << 20));
        order[p] = uint32_t(p);
    }
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return leafKey[a] < leafKey[b]; });

    const float reachSqr = float(radius * radius / (voxel * voxel)); // the kernel radius squared, in voxels
    const float inverseReachSqr = 1.0f / reachSqr;
    // The particles of one leaf are splatted into dense arrays over the leaf
    // and the kernel's reach around it, then the voxels they reached are
    // added to the chunk's grids: the inner loop is plain arithmetic, with no
    // tree lookups. Each voxel's sum still runs over the particles in order,
    // so the sums are those of voxel-by-voxel accumulation.
    const auto splatLeaf = [&](std::size_t first, std::size_t last, DenseSums& sums, Splat& into) {
        openvdb::CoordBBox box;
        for (std::size_t n = first; n != last; ++n)
            box.expand(openvdb::Coord::round(transform->worldToIndex(Vec3d(particles.position[order[n]]))));
        box.expand(reach);
        sums.reset(box);
        const openvdb::Coord dim = sums.dim;
        for (std::size_t n = first; n != last; ++n) {
            const std::size_t p = order[n];
            const openvdb::Vec3s v = particles.velocity[p], r = rest[p];
            const openvdb::Vec3d index = transform->worldToIndex(Vec3d(particles.position[p]));
            const openvdb::Coord centre = openvdb::Coord::round(index);
            // The kernel's sphere row by row along z (z is fastest in the
            // arrays, as in OpenVDB leaves): whole rows of 2 reach + 1 voxels,
            // weights clamped to zero outside the sphere, no branches.
            const float dz0 = float(double(centre.z() - reach) - index.z());
            for (int i = -reach; i <= reach; ++i) {
                const float dx = float(double(centre.x() + i) - index.x()), dx2 = dx * dx;
                if (dx2 >= reachSqr) continue;
                for (int j = -reach; j <= reach; ++j) {
                    const float dy = float(double(centre.y() + j) - index.y()), dxy2 = dx2 + dy * dy;
                    if (dxy2 >= reachSqr) continue;
                    const std::size_t row =
                        sums.row(centre.x() + i, centre.y() + j) + std::size_t(centre.z() - reach - sums.origin.z());
                    float* const w = &sums.w[row];
                    float *const vx = &sums.vx[row], *const vy = &sums.vy[row], *const vz = &sums.vz[row];
                    float *const rx = &sums.rx[row], *const ry = &sums.ry[row], *const rz = &sums.rz[row];
                    for (int k = 0; k <= 2 * reach; ++k) {
                        const float dz = dz0 + float(k);
                        const float q = std::max(0.0f, 1.0f - (dxy2 + dz * dz) * inverseReachSqr);
                        const float weight = q * q * q;
                        w[k] += weight;
                        vx[k] += v[0] * weight;
                        vy[k] += v[1] * weight;
                        vz[k] += v[2] * weight;
                        rx[k] += r[0] * weight;
                        ry[k] += r[1] * weight;
                        rz[k] += r[2] * weight;
                    }
                }
            }
        }
        auto weightAccessor = into.weight->getAccessor();
        auto momentumAccessor = into.momentum->getAccessor();
        auto restAccessor = into.rest->getAccessor();
        for (int x = 0; x < dim.x(); ++x)
            for (int y = 0; y < dim.y(); ++y) {
                const std::size_t row = sums.row(sums.origin.x() + x, sums.origin.y() + y);
                for (int z = 0; z < dim.z(); ++z) {
                    const std::size_t at = row + std::size_t(z);
                    if (sums.w[at] == 0.0f) continue;
                    const openvdb::Coord c = sums.origin.offsetBy(x, y, z);
                    weightAccessor.setValueOn(c, weightAccessor.getValue(c) + sums.w[at]);
                    momentumAccessor.setValueOn(c, momentumAccessor.getValue(c) +
                                                       openvdb::Vec3s(sums.vx[at], sums.vy[at], sums.vz[at]));
                    restAccessor.setValueOn(c, restAccessor.getValue(c) + openvdb::Vec3s(sums.rx[at], sums.ry[at], sums.rz[at]));
                }
            }
    };

    Splat total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, particles.size(), kParticlesPerChunk), Splat(transform),
        [&](const tbb::blocked_range<std::size_t>& range, const Splat&) {
            Splat partial(transform); // its own grids: the identity's are shared by every chunk
            DenseSums sums;
            for (std::size_t first = range.begin(); first != range.end();) {
                std::size_t last = first + 1;
                while (last != range.end() && leafKey[order[last]] == leafKey[order[first]]) ++last;
                splatLeaf(first, last, sums, partial);
                first = last;
            }
            return partial;
        },
        [](Splat a, const Splat& b) {
            openvdb::tools::compSum(*a.weight, *b.weight);
            openvdb::tools::compSum(*a.momentum, *b.momentum);
            openvdb::tools::compSum(*a.rest, *b.rest);
            return a;
        },
        tbb::simple_partitioner());

    DensityGrids grids;
    grids.density = openvdb::FloatGrid::create(0.0f);
    grids.density->setTransform(transform->copy());
    grids.velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grids.velocity->setTransform(transform->copy());
    openvdb::Vec3SGrid::Ptr restGrid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    restGrid->setTransform(transform->copy());

    auto density = grids.density->getAccessor();
    auto velocity = grids.velocity->getAccessor();
    auto restMean = restGrid->getAccessor();
    auto momentum = total.momentum->getConstAccessor();
    auto restSum = total.rest->getConstAccessor();
    for (auto it = total.weight->cbeginValueOn(); it; ++it) {
        const float w = *it;
        if (!(w > 0.0f)) continue;
        density.setValue(it.getCoord(), float(norm * w));
        velocity.setValue(it.getCoord(), momentum.getValue(it.getCoord()) / w);
        if (resolved.detail.enabled()) restMean.setValue(it.getCoord(), restSum.getValue(it.getCoord()) / w);
    }
    if (resolved.detail.enabled()) {
        const double softness = resolved.detail.edgeSoftness > 0.0 ? resolved.detail.edgeSoftness : norm;
        grids.density = detailedDensity(*grids.density, *restGrid, resolved.detail, softness);
    }
    grids.density->setName("density");
    grids.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    grids.velocity->setName("vel");
    grids.velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    return grids;
}

} // namespace vfield
