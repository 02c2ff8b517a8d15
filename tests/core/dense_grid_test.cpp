#include <vfield/core/dense_grid.h>

#include <catch2/catch.hpp>

using namespace vfield;

TEST_CASE("dense grid: the corners a read weighs have weights that sum to one and centre on the point", "[dense_grid]")
{
    const DenseGrid grid(Vec3d(-1, 2, 0), 0.5, {5, 4, 6}, 0.0f, 0.0f);
    DenseGrid linear = grid; // x + 2y - z at every point
    for (std::size_t n = 0; n < linear.size(); ++n) {
        const std::array<int, 3> ijk = linear.point(n);
        const Vec3d q = linear.position(ijk[0], ijk[1], ijk[2]);
        linear[n] = float(q[0] + 2.0 * q[1] - q[2]);
    }
    for (const Vec3d& p : {Vec3d(-0.8, 2.3, 1.1), Vec3d(0.99, 3.49, 2.5), Vec3d(-1, 2, 0)}) {
        double total = 0.0, spread = 0.0;
        Vec3d centre(0.0);
        grid.forCorners(p, [&](std::size_t n, double weight) {
            const std::array<int, 3> ijk = grid.point(n);
            total += weight;
            centre += grid.position(ijk[0], ijk[1], ijk[2]) * weight;
            spread += weight * linear[n];
        });
        CHECK(total == Approx(1.0));
        CHECK((centre - p).length() < 1e-12);
        // What forCorners spreads, at() reads back with the same weights.
        CHECK(spread == Approx(linear.at(p)).margin(1e-5));
    }
    // Beyond the lattice a point is taken at its nearest point inside.
    Vec3d centre(0.0);
    grid.forCorners(Vec3d(-5, 2.25, 100), [&](std::size_t n, double weight) {
        const std::array<int, 3> ijk = grid.point(n);
        centre += grid.position(ijk[0], ijk[1], ijk[2]) * weight;
    });
    CHECK((centre - Vec3d(-1, 2.25, 2.5)).length() < 1e-12);
}
