#include <vfield/core/vdb_file.h>
#include <vfield/volume/density_splat.h>
#include <vfield/volume/particle_grid.h>

#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/Count.h>
#include <openvdb/tools/Interpolation.h>

#include <catch2/catch.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

using namespace vfield;

namespace {

ParticleSet randomParticles(std::size_t n, uint64_t seed)
{
    ParticleSet particles;
    std::mt19937_64 random(seed);
    for (std::size_t i = 0; i < n; ++i) {
        const auto u = [&random] { return float(double(random() >> 11) / double(1ull << 53)); };
        particles.position.emplace_back(20 * u(), 10 * u(), 20 * u());
        particles.velocity.emplace_back(1.0f, 2.0f, -3.0f);
        particles.rest.push_back(particles.position.back());
        particles.id.push_back(uint32_t(i));
        particles.radius.push_back(0.5f);
        particles.cloud.push_back(0);
    }
    return particles;
}

} // namespace

TEST_CASE("density splat: the grid integrates to particles x density per particle", "[volume]")
{
    const ParticleSet particles = randomParticles(20000, 1);
    VolumeSettings options;
    options.voxelSize = 0.25;
    options.kernelRadius = 1.0;
    options.densityPerParticle = 0.5;
    const DensityGrids grids = splatParticles(particles, options);
    double integral = 0;
    for (auto it = grids.density->cbeginValueOn(); it; ++it) integral += *it;
    integral *= std::pow(options.voxelSize, 3);
    CHECK(integral == Approx(20000 * 0.5).epsilon(0.01));
    CHECK(grids.density->getName() == "density");
    CHECK(grids.velocity->getName() == "vel");
}

TEST_CASE("density splat: one particle's kernel is centred on it, as spread as the smooth kernel of radius R, and ends",
          "[volume]")
{
    ParticleSet one;
    one.position = {Vec3f(1.1f, 2.2f, 2.9f)};
    one.velocity = {Vec3f(4.0f, 5.0f, 6.0f)};
    one.id = {7};
    one.radius = {0.5f};
    one.cloud = {0};
    for (const double radius : {1.5, 3.0}) {
        VolumeSettings options;
        options.voxelSize = 0.5;
        options.kernelRadius = radius;
        options.densityPerParticle = 2.0;
        options.cutoff = 0.0; // the whole kernel, its faint fringe too
        const DensityGrids grids = splatParticles(one, options);
        double mass = 0.0;
        Vec3d first(0.0), second(0.0), farthest(0.0);
        for (auto it = grids.density->cbeginValueOn(); it; ++it) {
            if (*it == 0.0f) continue;
            const Vec3d p = grids.density->indexToWorld(it.getCoord());
            mass += *it;
            for (int axis = 0; axis < 3; ++axis) {
                first[axis] += *it * p[axis];
                second[axis] += *it * p[axis] * p[axis];
                farthest[axis] = std::max(farthest[axis], std::abs(p[axis] - double(one.position[0][axis])));
            }
            const openvdb::Vec3s v = grids.velocity->tree().getValue(it.getCoord());
            CHECK(v[0] == Approx(4.0f));
            CHECK(v[1] == Approx(5.0f));
            CHECK(v[2] == Approx(6.0f));
        }
        CHECK(mass * std::pow(0.5, 3) == Approx(2.0));
        for (int axis = 0; axis < 3; ++axis) {
            const double mean = first[axis] / mass, variance = second[axis] / mass - mean * mean;
            INFO("radius " << radius << ", axis " << axis << ": variance " << variance << ", smooth kernel's "
                           << radius * radius / 11.0);
            CHECK(mean == Approx(one.position[0][axis]).margin(1e-5));
            // The blur comes in passes adding 2/3 voxel^2 each: within half a pass.
            CHECK(std::abs(variance - radius * radius / 11.0) < 0.34 * 0.25);
            // No further than the smooth kernel reaches, plus a voxel.
            CHECK(farthest[axis] < radius + 0.5);
        }
    }
}

TEST_CASE("particle grid: every particle is stored with its attributes", "[volume]")
{
    const ParticleSet particles = randomParticles(5000, 2);
    const openvdb::GridBase::Ptr grid = makeParticleGrid(particles);
    const auto points = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(grid);
    REQUIRE(points);
    CHECK(points->getName() == "particles");
    CHECK(openvdb::points::pointCount(points->tree()) == 5000);
    const auto& descriptor = points->tree().cbeginLeaf()->attributeSet().descriptor();
    for (const char* name : {"P", "v", "rest", "id", "pscale"})
        CHECK(descriptor.find(name) != openvdb::points::AttributeSet::INVALID_POS);
    CHECK(descriptor.find("rest2") == openvdb::points::AttributeSet::INVALID_POS);

    // With dual rest, the second rest and the blend go with them.
    ParticleSet dual = particles;
    dual.rest2 = dual.position;
    dual.rest2Weight = 0.25f;
    const auto dualPoints = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(makeParticleGrid(dual));
    CHECK(dualPoints->tree().cbeginLeaf()->attributeSet().descriptor().find("rest2") !=
          openvdb::points::AttributeSet::INVALID_POS);
    CHECK(dualPoints->metaValue<float>("rest2Weight") == 0.25f);
}

namespace {

VolumeSettings detailOptions()
{
    VolumeSettings options;
    options.voxelSize = 0.5;
    options.kernelRadius = 1.25;
    options.detail.voxelSize = 0.25;
    options.detail.frequency = 0.8;
    options.detail.amplitude = 1.0;
    return options;
}

/// The largest difference between a grid and another shifted by a whole number of voxels.
double largestDifference(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b, const openvdb::Coord& shift)
{
    double largest = 0.0;
    const auto bAccessor = b.getConstAccessor();
    for (auto it = a.cbeginValueOn(); it; ++it)
        largest = std::max(largest, std::abs(double(*it) - double(bAccessor.getValue(it.getCoord() + shift))));
    const auto aAccessor = a.getConstAccessor();
    for (auto it = b.cbeginValueOn(); it; ++it)
        largest = std::max(largest, std::abs(double(*it) - double(aAccessor.getValue(it.getCoord() - shift))));
    return largest;
}

} // namespace

TEST_CASE("density detail: a finer grid with structure the splat does not have", "[volume]")
{
    const ParticleSet particles = randomParticles(20000, 3);
    VolumeSettings plain = detailOptions();
    plain.detail.voxelSize = 0.0;
    const DensityGrids coarse = splatParticles(particles, plain);
    const DensityGrids detailed = splatParticles(particles, detailOptions());
    CHECK(detailed.density->voxelSize()[0] == Approx(0.25));
    CHECK(detailed.velocity->voxelSize()[0] == Approx(0.5));
    CHECK(detailed.density->getName() == "density");
    // The noise moves the density away from the splat's, inside and at the edges, both ways.
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> base(*coarse.density);
    std::size_t raised = 0, lowered = 0, total = 0;
    for (auto it = detailed.density->cbeginValueOn(); it; ++it, ++total) {
        const double smooth = base.wsSample(detailed.density->transform().indexToWorld(it.getCoord()));
        raised += *it > 1.1 * smooth;
        lowered += *it < 0.9 * smooth;
    }
    CHECK(raised > total / 20);
    CHECK(lowered > total / 10);
}

TEST_CASE("density detail travels with the material: moved particles keep their rest, the detail moves with them", "[volume]")
{
    ParticleSet particles = randomParticles(20000, 4);
    const DensityGrids before = splatParticles(particles, detailOptions());
    // Two splat voxels along x and one along z: whole voxels of both grids.
    const Vec3f move(1.0f, 0.0f, 0.5f);
    for (Vec3f& p : particles.position) p += move;
    const DensityGrids moved = splatParticles(particles, detailOptions());
    CHECK(largestDifference(*before.density, *moved.density, openvdb::Coord(4, 0, 2)) < 1e-4);

    // Without rest positions the same move changes the detail: it would swim.
    for (std::size_t i = 0; i < particles.size(); ++i) particles.rest[i] = particles.position[i];
    const DensityGrids swum = splatParticles(particles, detailOptions());
    CHECK(largestDifference(*before.density, *swum.density, openvdb::Coord(4, 0, 2)) > 0.05);
}

namespace {

/// The relative spread the detail adds: the standard deviation of detailed
/// over smooth density, where the smooth density is well inside the cloud.
double detailContrast(const DensityGrids& detailed, const openvdb::FloatGrid& smooth)
{
    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> base(smooth);
    double sum = 0.0, squares = 0.0;
    std::size_t n = 0;
    const double inside = 0.5 * openvdb::tools::minMax(smooth.tree()).max();
    for (auto it = detailed.density->cbeginValueOn(); it; ++it) {
        const double rho = base.wsSample(detailed.density->transform().indexToWorld(it.getCoord()));
        if (rho < inside) continue;
        const double ratio = double(*it) / rho;
        sum += ratio;
        squares += ratio * ratio;
        ++n;
    }
    const double mean = sum / double(n);
    return std::sqrt(squares / double(n) - mean * mean);
}

} // namespace

TEST_CASE("density detail with dual rest: a rest reset at zero weight does not show, and the blend keeps the contrast",
          "[volume]")
{
    ParticleSet particles = randomParticles(40000, 5);
    const DensityGrids single = splatParticles(particles, detailOptions());

    // rest2 anywhere at weight 0: the detail is rest's alone, to the bit.
    particles.rest2 = particles.position;
    for (Vec3f& p : particles.rest2) p += Vec3f(3.7f, -1.3f, 2.1f);
    particles.rest2Weight = 0.0f;
    CHECK(largestDifference(*single.density, *splatParticles(particles, detailOptions()).density, openvdb::Coord(0)) == 0.0);
    // At weight 1 it is rest2's: other detail.
    particles.rest2Weight = 1.0f;
    const DensityGrids second = splatParticles(particles, detailOptions());
    CHECK(largestDifference(*single.density, *second.density, openvdb::Coord(0)) > 0.05);

    // Halfway, two independent noises averaged would lose 1 - 1/sqrt(2) of
    // their contrast (29%); normalized, the blend keeps it.
    particles.rest2Weight = 0.5f;
    const DensityGrids blended = splatParticles(particles, detailOptions());
    VolumeSettings plain = detailOptions();
    plain.detail.voxelSize = 0.0;
    const DensityGrids smooth = splatParticles(particles, plain);
    const double contrastSingle = detailContrast(single, *smooth.density),
                 contrastBlended = detailContrast(blended, *smooth.density);
    INFO("detail contrast: " << contrastSingle << " from rest, " << contrastBlended << " blended");
    CHECK(contrastBlended == Approx(contrastSingle).epsilon(0.12));
}

namespace {

/// Particles uniform in a ball of the given radius about (10, 10, 10), each at rest where it is.
ParticleSet ballOfParticles(std::size_t n, double radius, uint64_t seed)
{
    ParticleSet particles;
    std::mt19937_64 random(seed);
    const auto u = [&random] { return 2.0 * double(random() >> 11) / double(1ull << 53) - 1.0; };
    while (particles.size() < n) {
        const Vec3d p(u(), u(), u());
        if (p.length() > 1.0) continue;
        particles.position.emplace_back(Vec3f(Vec3d(10.0) + p * radius));
        particles.velocity.emplace_back(0.0f);
        particles.rest.push_back(particles.position.back());
        particles.id.push_back(uint32_t(particles.size()));
        particles.radius.push_back(0.5f);
        particles.cloud.push_back(0);
    }
    return particles;
}

/// Displaced detail over a range of 0.3 x (1 + 0.6 + 0.36 + 0.216) / 0.25 =
/// 2.61 units: 1.46 out and 1.15 in; the surface where the splat's density is 1.
VolumeSettings displacedOptions()
{
    VolumeSettings options;
    options.voxelSize = 0.5;
    options.kernelRadius = 1.25;
    options.detail.voxelSize = 0.25;
    options.detail.style = DetailStyle::Displaced;
    options.detail.frequency = 0.25;
    options.detail.octaves = 4;
    options.detail.gain = 0.6;
    options.detail.amplitude = 0.3;
    options.detail.edgeSoftness = 2.0;
    return options;
}

/// The distance from (10, 10, 10) of a grid's voxel.
double fromCentre(const openvdb::FloatGrid& grid, const openvdb::Coord& voxel)
{
    return (grid.indexToWorld(voxel) - openvdb::Vec3d(10.0)).length();
}

} // namespace

TEST_CASE("displaced detail: lumps stand out beyond the particles and creases cut in, as far as its range, and the "
          "cloud keeps its size",
          "[volume]")
{
    const ParticleSet particles = ballOfParticles(20000, 8.0, 6);
    const VolumeSettings options = displacedOptions();
    REQUIRE(options.detail.displacementRange() == Approx(2.61).epsilon(1e-3));
    const double outward = 0.56 * options.detail.displacementRange(), inward = 0.44 * options.detail.displacementRange();
    VolumeSettings plainOptions = options;
    plainOptions.detail.voxelSize = 0.0;
    const DensityGrids plain = splatParticles(particles, plainOptions);
    const DensityGrids displaced = splatParticles(particles, options);
    const double surfaceDensity = 0.5 * options.detail.edgeSoftness;

    // The splat's surface: the farthest voxel at least as dense as it.
    double surface = 0.0, plainVolume = 0.0;
    for (auto it = plain.density->cbeginValueOn(); it; ++it)
        if (*it >= surfaceDensity) {
            surface = std::max(surface, fromCentre(*plain.density, it.getCoord()));
            plainVolume += std::pow(plain.density->voxelSize()[0], 3);
        }
    REQUIRE(surface > 7.5);

    const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> splat(*plain.density);
    double farthest = 0.0, volume = 0.0;
    std::size_t nearSurface = 0, carved = 0, deep = 0, deepAtLeastEdge = 0;
    const double fineVolume = std::pow(displaced.density->voxelSize()[0], 3);
    for (auto it = displaced.density->cbeginValueOn(); it; ++it) {
        const double r = fromCentre(*displaced.density, it.getCoord());
        if (*it >= surfaceDensity) {
            farthest = std::max(farthest, r);
            volume += fineVolume;
        }
        if (r < surface - inward - 1.0) {
            ++deep;
            deepAtLeastEdge += *it >= options.detail.edgeSoftness;
        }
    }
    // Creases: fine voxels within the splat's surface, above its deepest
    // crease, that the displaced surface has left empty.
    const auto accessor = displaced.density->getConstAccessor();
    const openvdb::CoordBBox box = displaced.density->evalActiveVoxelBoundingBox();
    for (auto c = box.begin(); c; ++c) {
        const double r = fromCentre(*displaced.density, *c);
        if (r < surface - 0.5 * inward || r > surface - 0.5) continue;
        if (splat.wsSample(displaced.density->indexToWorld(*c)) < surfaceDensity) continue;
        ++nearSurface;
        carved += accessor.getValue(*c) < 0.1 * surfaceDensity;
    }
    INFO("splat surface " << surface << ", farthest displaced " << farthest << "; " << carved << " of " << nearSurface
                          << " voxels just inside the surface carved; volume " << volume << " against " << plainVolume);
    CHECK(farthest > surface + 0.5 * outward);
    CHECK(farthest < surface + outward + 0.5);
    CHECK(carved > nearSurface / 10);
    CHECK(volume == Approx(plainVolume).epsilon(0.15));
    // Deep inside, beyond the reach of every crease, the cloud is whole and at least edgeSoftness dense.
    CHECK(deep > 1000);
    CHECK(deepAtLeastEdge == deep);
}

TEST_CASE("displaced detail travels with the material and is the same for any thread count", "[volume]")
{
    ParticleSet particles = ballOfParticles(20000, 8.0, 7);
    const VolumeSettings options = displacedOptions();
    const DensityGrids before = splatParticles(particles, options);
    {
        const tbb::global_control oneThread(tbb::global_control::max_allowed_parallelism, 1);
        CHECK(largestDifference(*before.density, *splatParticles(particles, options).density, openvdb::Coord(0)) == 0.0);
    }
    // Two splat voxels along x and one along z, rest positions kept: the
    // lumps beyond the particles, where rest is carried off the surface, move too.
    const Vec3f move(1.0f, 0.0f, 0.5f);
    for (Vec3f& p : particles.position) p += move;
    const DensityGrids moved = splatParticles(particles, options);
    CHECK(largestDifference(*before.density, *moved.density, openvdb::Coord(4, 0, 2)) < 1e-3);
    // At rest where they now are, the same particles grow other lumps.
    particles.rest = particles.position;
    CHECK(largestDifference(*before.density, *splatParticles(particles, options).density, openvdb::Coord(4, 0, 2)) > 0.5);
}

TEST_CASE("density splat: the same particles in another order give the same grids, bit for bit, in every detail style",
          "[volume]")
{
    // Velocities, a second rest and peaks that differ from particle to
    // particle, so that every sum adds terms of many sizes; the detail's
    // thresholds and condensation's shares turn any difference in them into
    // visible ones.
    ParticleSet particles = ballOfParticles(20000, 8.0, 11);
    std::mt19937_64 random(3);
    const auto u = [&random] { return float(2.0 * double(random() >> 11) / double(1ull << 53) - 1.0); };
    for (std::size_t i = 0; i < particles.size(); ++i) {
        particles.velocity[i] = Vec3f(5.0f * u(), 5.0f * u(), 5.0f * u());
        particles.rest2.push_back(particles.position[i] + Vec3f(3.0f * u(), 3.0f * u(), 3.0f * u()));
        particles.peak.push_back(particles.position[i].y() + 2.0f + 2.0f * u());
        particles.radius[i] = 0.5f + 0.2f * u();
    }
    particles.rest2Weight = 0.35f;
    std::vector<uint32_t> order(particles.size());
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), std::mt19937_64(5));
    ParticleSet shuffled = particles;
    shuffled.reorder(order);

    for (const DetailStyle style : {DetailStyle::Erode, DetailStyle::Billows, DetailStyle::Displaced}) {
        VolumeSettings options = displacedOptions();
        options.detail.style = style;
        options.condensation.depth = 3.0;
        const DensityGrids a = splatParticles(particles, options), b = splatParticles(shuffled, options);
        INFO(enumName(style));
        CHECK(a.density->activeVoxelCount() > 10000);
        CHECK(gridChecksum(*a.density) == gridChecksum(*b.density));
        CHECK(gridChecksum(*a.velocity) == gridChecksum(*b.velocity));
    }
    // The voxel and the kernel from the particles' mean radius.
    const VolumeSettings fromRadii;
    CHECK(gridChecksum(*splatParticles(particles, fromRadii).density) ==
          gridChecksum(*splatParticles(shuffled, fromRadii).density));
}

TEST_CASE("displaced detail draws lumps only within its range of the surface, none in the faint fringe beyond it", "[volume]")
{
    // A ball and a fringe of sparse particles around it, out to 3 times its
    // radius, nowhere as dense as the surface: as the specks a swirling
    // cloud sheds. Fast sweeping measures the fringe's distance within it,
    // around its gaps, or not at all in specks with no surface of their own;
    // taken for closest points, those drew lumps 26 to 28 units out.
    ParticleSet particles = ballOfParticles(20000, 8.0, 6);
    const ParticleSet fringe = ballOfParticles(8000, 24.0, 7);
    for (std::size_t i = 0; i < fringe.size(); ++i) {
        if ((Vec3d(fringe.position[i]) - Vec3d(10.0)).length() < 10.0) continue;
        particles.position.push_back(fringe.position[i]);
        particles.velocity.push_back(fringe.velocity[i]);
        particles.rest.push_back(fringe.rest[i]);
        particles.id.push_back(uint32_t(particles.size()));
        particles.radius.push_back(fringe.radius[i]);
        particles.cloud.push_back(0);
    }
    VolumeSettings options = displacedOptions();
    options.detail.amplitude = 1.0;    // a range of 8.7 units, 17 splat voxels
    options.detail.edgeSoftness = 6.0; // a surface at 3, over the fringe's overlapping kernels
    const double surfaceDensity = 0.5 * options.detail.edgeSoftness;
    VolumeSettings plainOptions = options;
    plainOptions.detail.voxelSize = 0.0;
    const DensityGrids plain = splatParticles(particles, plainOptions);
    double surface = 0.0, fringeDensity = 0.0;
    for (auto it = plain.density->cbeginValueOn(); it; ++it) {
        const double r = fromCentre(*plain.density, it.getCoord());
        if (*it >= surfaceDensity) surface = std::max(surface, r);
        if (r > 11.0) fringeDensity = std::max(fringeDensity, double(*it));
    }
    INFO("splat surface " << surface << ", fringe density up to " << fringeDensity);
    REQUIRE(surface < 9.0);
    REQUIRE(fringeDensity < surfaceDensity);

    const DensityGrids displaced = splatParticles(particles, options);
    double farthest = 0.0;
    for (auto it = displaced.density->cbeginValueOn(); it; ++it)
        if (*it >= surfaceDensity) farthest = std::max(farthest, fromCentre(*displaced.density, it.getCoord()));
    INFO("farthest displaced " << farthest << ", range " << options.detail.displacementRange());
    const double outward = 0.56 * options.detail.displacementRange();
    CHECK(farthest > surface + 0.5 * outward);
    CHECK(farthest < surface + outward + 0.5);
}

TEST_CASE("displaced detail leaves a cloud nowhere as dense as its surface as the splat made it", "[volume]")
{
    const ParticleSet particles = ballOfParticles(200, 8.0, 8);
    VolumeSettings options = displacedOptions();
    options.detail.edgeSoftness = 4.0; // a surface at 2, over the peaks of these few particles
    options.cutoff = 0.0;
    VolumeSettings plainOptions = options;
    plainOptions.detail.voxelSize = 0.0;
    const DensityGrids displaced = splatParticles(particles, options), plain = splatParticles(particles, plainOptions);
    REQUIRE(openvdb::tools::minMax(plain.density->tree()).max() < 0.5 * options.detail.edgeSoftness);
    CHECK(displaced.density->voxelSize()[0] == Approx(0.5));
    CHECK(largestDifference(*plain.density, *displaced.density, openvdb::Coord(0)) == 0.0);
}

TEST_CASE("displaced detail: a range over more than 64 splat voxels is refused, naming the amplitude", "[volume]")
{
    VolumeSettings options = displacedOptions();
    options.detail.amplitude = 4.0;
    options.detail.frequency = 0.05; // 4 x 2.18 / 0.05 = 174 units, 348 voxels of 0.5
    CHECK_THROWS_WITH(options.validate(), Catch::Contains("detail/amplitude") && Catch::Contains("more than 64 voxels"));
    options.detail.style = DetailStyle::Billows;
    CHECK_NOTHROW(options.validate());
}

TEST_CASE("density splat: the cutoff leaves out the kernels' fringe below its share of a lone particle's peak, "
          "keeping the grid's bounds and a velocity only where there is density",
          "[volume]")
{
    ParticleSet one;
    one.position = {Vec3f(0.5f, 1.0f, -0.5f)}; // on a voxel's centre: its peak is a lone particle's
    one.velocity = {Vec3f(0.0f)};
    one.id = {1};
    one.radius = {0.5f};
    one.cloud = {0};
    VolumeSettings options;
    options.voxelSize = 0.5;
    options.kernelRadius = 3.0;
    options.cutoff = 0.0;
    const openvdb::FloatGrid::Ptr whole = splatParticles(one, options).density;
    options.cutoff = 0.01;
    const DensityGrids cutGrids = splatParticles(one, options);
    const openvdb::FloatGrid::Ptr cut = cutGrids.density;
    float peak = 0.0f;
    for (auto it = whole->cbeginValueOn(); it; ++it) peak = std::max(peak, *it);
    // Every voxel at or above 1% of the peak is kept as it was; every one
    // below is gone, but for those on the faces of the active box.
    const openvdb::CoordBBox bounds = whole->evalActiveVoxelBoundingBox();
    const auto onFace = [&bounds](const openvdb::Coord& c) {
        return c.x() == bounds.min().x() || c.x() == bounds.max().x() || c.y() == bounds.min().y() || c.y() == bounds.max().y() ||
               c.z() == bounds.min().z() || c.z() == bounds.max().z();
    };
    auto kept = cut->getConstAccessor();
    uint64_t below = 0;
    for (auto it = whole->cbeginValueOn(); it; ++it) {
        if (*it >= 0.01f * peak || onFace(it.getCoord())) {
            CHECK(kept.isValueOn(it.getCoord()));
            CHECK(kept.getValue(it.getCoord()) == *it);
        } else {
            ++below;
            CHECK_FALSE(kept.isValueOn(it.getCoord()));
            CHECK(kept.getValue(it.getCoord()) == 0.0f);
        }
    }
    CHECK(below > 0);
    CHECK(cut->activeVoxelCount() + below == whole->activeVoxelCount());
    CHECK(cut->evalActiveVoxelBoundingBox() == bounds);
    // The velocity is where the density is (it is on the same voxels here).
    for (auto it = cutGrids.velocity->cbeginValueOn(); it; ++it) CHECK(kept.isValueOn(it.getCoord()));
    CHECK(cutGrids.velocity->activeVoxelCount() == cut->activeVoxelCount());
}

TEST_CASE("particle grid: compact precision keeps positions within a 65536th of a voxel, velocities and rest as 16-bit "
          "floats and pscale within a 255th of a unit",
          "[volume]")
{
    ParticleSet particles = randomParticles(5000, 3);
    std::mt19937 random(4);
    for (std::size_t i = 0; i < particles.size(); ++i) {
        particles.radius[i] = std::uniform_real_distribution<float>(0.05f, 0.95f)(random);
        particles.velocity[i] = Vec3f(std::normal_distribution<float>(0.0f, 5.0f)(random),
                                      std::normal_distribution<float>(0.0f, 5.0f)(random), 0.001f * float(i));
    }
    const auto grid =
        openvdb::gridPtrCast<openvdb::points::PointDataGrid>(makeParticleGrid(particles, ParticlePrecision::Compact));
    REQUIRE(grid);
    const double voxel = grid->voxelSize()[0];
    std::map<int32_t, std::size_t> byId;
    for (std::size_t i = 0; i < particles.size(); ++i) byId[particles.id[i]] = i;
    std::size_t seen = 0;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
        CHECK(leaf->constAttributeArray("P").codecType() == "fxpt16");
        CHECK(leaf->constAttributeArray("pscale").codecType() == "ufxpt8");
        const openvdb::points::AttributeHandle<openvdb::Vec3f> position(leaf->constAttributeArray("P")),
            velocity(leaf->constAttributeArray("v")), rest(leaf->constAttributeArray("rest"));
        const openvdb::points::AttributeHandle<int32_t> id(leaf->constAttributeArray("id"));
        const openvdb::points::AttributeHandle<float> radius(leaf->constAttributeArray("pscale"));
        for (auto index = leaf->beginIndexOn(); index; ++index, ++seen) {
            const std::size_t i = byId.at(id.get(*index));
            const Vec3d p = grid->indexToWorld(index.getCoord().asVec3d() + position.get(*index));
            CHECK((p - Vec3d(particles.position[i])).length() <= voxel / 65536.0 * 2.0);
            for (int axis = 0; axis < 3; ++axis) {
                CHECK(std::abs(velocity.get(*index)[axis] - particles.velocity[i][axis]) <=
                      std::abs(particles.velocity[i][axis]) / 2048.0f + 1e-7f);
                CHECK(std::abs(rest.get(*index)[axis] - particles.rest[i][axis]) <=
                      std::abs(particles.rest[i][axis]) / 2048.0f + 1e-7f);
            }
            CHECK(std::abs(radius.get(*index) - particles.radius[i]) <= 1.0f / 255.0f + 1e-6f); // truncated, not rounded
        }
    }
    CHECK(seen == particles.size());
}
