#include <vfield/core/error.h>
#include <vfield/mesh/procedural.h>
#include <vfield/mesh/tessellate.h>

#include <catch2/catch.hpp>

using namespace vfield;

namespace {

double longestEdge(const TriangleMesh& mesh)
{
    double longest = 0;
    for (const Vec3ui& t : mesh.triangles)
        for (int c = 0; c < 3; ++c)
            longest = std::max(longest, (Vec3d(mesh.points[t[c]]) - Vec3d(mesh.points[t[(c + 1) % 3]])).length());
    return longest;
}

} // namespace

TEST_CASE("tessellate: no edge is longer than the target and the solid is unchanged", "[mesh]")
{
    const TriangleMesh box = makeBox({{0, 0, 0}, {2, 3, 4}});
    const TriangleMesh fine = tessellate(box, 0.5);
    CHECK(longestEdge(fine) <= 0.5);
    CHECK(fine.triangleCount() > 100);
    CHECK(analyzeTopology(fine).isClosed());                 // still closed and consistently wound
    CHECK(signedVolume(fine) == Approx(24.0).epsilon(1e-9)); // same shape, same orientation
    CHECK(fine.bounds().min() == box.bounds().min());
    CHECK(fine.bounds().max() == box.bounds().max());
}

TEST_CASE("tessellate: normals of the pieces keep their triangle's orientation", "[mesh]")
{
    TriangleMesh triangle;
    triangle.points = {{0, 0, 0}, {4, 0, 0}, {0, 3, 0}};
    triangle.triangles = {{0, 1, 2}};
    const TriangleMesh fine = tessellate(triangle, 1.0);
    double area = 0;
    for (std::size_t i = 0; i < fine.triangleCount(); ++i) {
        CHECK(fine.areaVector(i)[2] > 0.0);
        area += 0.5 * fine.areaVector(i).length();
    }
    CHECK(area == Approx(6.0));
}

TEST_CASE("tessellate: an absurd target is refused before allocating", "[mesh]")
{
    CHECK_THROWS_WITH(tessellate(makeBox({}), 1e-5), Catch::Contains("would make about"));
    CHECK_THROWS_AS(tessellate(makeBox({}), 0.0), ValueError);
}
