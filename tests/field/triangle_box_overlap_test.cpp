#include <vfield/field/triangle_box_overlap.h>

#include <catch2/catch.hpp>

using namespace vfield;

namespace {
const Vec3d kCenter(0.0), kHalf(1.0); // the box [-1, 1]^3
}

TEST_CASE("triangle-box overlap: a triangle inside or through the box overlaps it", "[field]")
{
    CHECK(triangleOverlapsBox(kCenter, kHalf, {-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0, 0.5, 0}));
    // Much larger than the box, passing through it: no corner inside.
    CHECK(triangleOverlapsBox(kCenter, kHalf, {-10, -10, 0.3}, {10, -10, 0.3}, {0, 20, 0.3}));
}

TEST_CASE("triangle-box overlap: touching a face or an edge or a corner counts", "[field]")
{
    CHECK(triangleOverlapsBox(kCenter, kHalf, {1, -3, -3}, {1, 3, -3}, {1, 0, 3})); // lies in the face x = 1
    CHECK(triangleOverlapsBox(kCenter, kHalf, {1, 1, 1}, {2, 1, 1}, {2, 2, 2}));    // one corner on the box's corner
    CHECK(triangleOverlapsBox(kCenter, kHalf, {1, 1, -5}, {1, 1, 5}, {3, 3, 0}));   // an edge along the box's edge
}

TEST_CASE("triangle-box overlap: separated by an axis the bounding boxes miss", "[field]")
{
    CHECK_FALSE(triangleOverlapsBox(kCenter, kHalf, {1.01, -3, -3}, {1.01, 3, -3}, {1.01, 0, 3}));
    // The plane x + y + z = 3.1 passes the corner (1,1,1) (sum 3) although the
    // triangle's bounding box covers the whole box; 2.9 cuts the corner.
    CHECK_FALSE(triangleOverlapsBox(kCenter, kHalf, {3.1, 0, 0}, {0, 3.1, 0}, {0, 0, 3.1}));
    CHECK(triangleOverlapsBox(kCenter, kHalf, {2.9, 0, 0}, {0, 2.9, 0}, {0, 0, 2.9}));
    // An edge axis separates: a thin triangle beside the box's edge, diagonally.
    CHECK_FALSE(triangleOverlapsBox(kCenter, kHalf, {2.05, 0, -5}, {0, 2.05, -5}, {1.025, 1.025, 5}));
    CHECK(triangleOverlapsBox(kCenter, kHalf, {1.95, 0, -5}, {0, 1.95, -5}, {0.975, 0.975, 5}));
}
