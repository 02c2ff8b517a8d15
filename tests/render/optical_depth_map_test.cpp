#include <vfield/render/optical_depth_map.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace vfield;

namespace {

/// Two lumpy balls of density, one above and beside the other with empty
/// space between (many leaves of it along an oblique light), at world
/// coordinates off the voxels' (a translated transform).
openvdb::FloatGrid::Ptr twoLumpyBalls(double voxel)
{
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    grid->transform().postTranslate(openvdb::Vec3d(0.13, -0.41, 0.27));
    auto accessor = grid->getAccessor();
    const struct {
        Vec3d centre;
        double radius;
    } balls[] = {{{0, 0, 0}, 6.0}, {{9, 30, 4}, 4.0}};
    for (const auto& ball : balls) {
        const openvdb::CoordBBox box =
            grid->transform().worldToIndexNodeCentered(openvdb::BBoxd(ball.centre - ball.radius, ball.centre + ball.radius));
        for (auto c = box.begin(); c; ++c) {
            const Vec3d p = grid->transform().indexToWorld(*c), d = p - ball.centre;
            if (d.length() > ball.radius) continue;
            accessor.setValueOn(*c, float(1.0 + 0.8 * std::sin(1.3 * p[0]) * std::sin(0.9 * p[1]) * std::sin(1.7 * p[2])));
        }
    }
    return grid;
}

/// The density's integral from p towards the light, marched in steps of a
/// hundredth of a voxel through the trilinear density.
double marchedDepth(const openvdb::FloatGrid& density, const Vec3d& p, const Vec3d& towards)
{
    TrilinearSampler<openvdb::FloatTree> sampler(density.tree());
    const double step = 0.01 * density.voxelSize()[0];
    double depth = 0.0;
    for (double t = 0.5 * step; t < 80.0; t += step)
        depth += sampler.atIndex(density.transform().worldToIndex(p + towards * t)) * step;
    return depth;
}

} // namespace

TEST_CASE("an optical depth map holds the density's integral towards the light, across empty space too", "[render][light]")
{
    const double voxel = 0.5;
    const openvdb::FloatGrid::Ptr density = twoLumpyBalls(voxel);
    const Vec3d sources[] = {Vec3d(0.3, 0.9, 0.1).unit(), Vec3d(0, 1, 0), Vec3d(-0.5, 0.2, -0.84).unit()};
    std::mt19937_64 random(3);
    std::uniform_real_distribution<double> inBall(-6.0, 6.0);
    for (const Vec3d& towards : sources) {
        const OpticalDepthMap map(density, towards);
        OpticalDepthMap::Reader reader(map);
        // Depths, their errors and transmittances through a tenth of the density (optical depths about 1).
        double depths = 0.0, errors = 0.0, absoluteErrors = 0.0, transmittance = 0.0, mappedTransmittance = 0.0;
        int points = 0, shadowedFromAfar = 0;
        while (points < 400) {
            const Vec3d p(inBall(random), inBall(random), inBall(random));
            if (p.length() > 6.5) continue;
            ++points;
            const double exact = marchedDepth(*density, p, towards), mapped = reader.at(p);
            depths += exact;
            errors += mapped - exact;
            absoluteErrors += std::abs(mapped - exact);
            transmittance += std::exp(-0.1 * exact);
            mappedTransmittance += std::exp(-0.1 * mapped);
            // Under the upper ball, beyond the empty stretch between them.
            if (marchedDepth(*density, p + towards * 15.0, towards) > 1.0) ++shadowedFromAfar;
        }
        INFO("towards " << towards << ": depths " << depths / points << " on average, off by " << errors / points << " ("
                        << absoluteErrors / points << " unsigned); transmittance " << mappedTransmittance / points << " against "
                        << transmittance / points << "; " << shadowedFromAfar << " points under the far ball");
        // Unbiased: the errors of reading between columns a voxel apart
        // cancel (measured: -0.2 to -0.6% of the depth, 1.5 to 1.7%
        // unsigned; the transmittance within 0.2%).
        CHECK(std::abs(errors) < 0.01 * depths);
        CHECK(absoluteErrors < 0.03 * depths);
        CHECK(mappedTransmittance == Approx(transmittance).epsilon(0.005));
        if (towards == sources[0]) {
            CHECK(shadowedFromAfar > 100);
            // In the empty stretch between the balls, far from both: the upper
            // ball's depth, as a sample near the lower ball's top reads it.
            for (double t = 8.0; t < 20.0; t += 1.0) {
                const Vec3d p = towards * t;
                INFO("in the gap at " << p);
                CHECK(reader.at(p) == Approx(marchedDepth(*density, p, towards)).epsilon(0.02));
            }
        }
    }
    // Where no density lies towards the light, none is counted.
    const OpticalDepthMap map(density, Vec3d(0, 1, 0));
    OpticalDepthMap::Reader reader(map);
    CHECK(reader.at(Vec3d(0, 8.0, 0)) == 0.0);
}

TEST_CASE("an optical depth map lets through as much light as a sharp-edged cloud's own rays do", "[render][light]")
{
    // A ball of constant density, nothing to a voxel's ramp to 2: the depth
    // bends from none to growing fast at its lit side. Read across or along
    // that bend, its depth comes out too deep just inside, and the ball lets
    // through too little light; marched from p to the columns, 1 to 2% too little.
    const double voxel = 0.25, radius = 6.0;
    auto density = openvdb::FloatGrid::create(0.0f);
    density->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    auto accessor = density->getAccessor();
    const openvdb::CoordBBox box(openvdb::Coord(-25), openvdb::Coord(25));
    for (auto c = box.begin(); c; ++c)
        if (density->transform().indexToWorld(*c).length() < radius) accessor.setValueOn(*c, 2.0f);
    std::mt19937_64 random(3);
    std::uniform_real_distribution<double> inBox(-radius, radius);
    for (const Vec3d& towards : {Vec3d(0.3, 0.5, 1.0).unit(), Vec3d(1, 0.2, 0).unit(), Vec3d(0.3, 0.4, -1.0).unit()}) {
        const OpticalDepthMap map(density, towards);
        OpticalDepthMap::Reader reader(map);
        double transmittance = 0.0, mappedTransmittance = 0.0;
        for (int points = 0; points < 2000;) {
            const Vec3d p(inBox(random), inBox(random), inBox(random));
            if (p.length() > radius) continue;
            ++points;
            transmittance += std::exp(-marchedDepth(*density, p, towards));
            mappedTransmittance += std::exp(-reader.at(p));
        }
        INFO("towards " << towards << ": " << mappedTransmittance / 2000 << " against " << transmittance / 2000);
        CHECK(mappedTransmittance == Approx(transmittance).epsilon(0.03));
    }
}
