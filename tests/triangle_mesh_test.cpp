#include <vfield/mesh/procedural.h>
#include <vfield/mesh/triangle_mesh.h>

#include <catch2/catch.hpp>

using namespace vfield;

TEST_CASE("triangle mesh: zero-area triangles are removed and counted", "[mesh]")
{
    TriangleMesh mesh;
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
    mesh.triangles = {{0, 1, 2}, {0, 0, 1}, {0, 1, 3}, {2, 1, 0}};
    CHECK(removeDegenerateTriangles(mesh) == 2); // a repeated corner, collinear corners
    CHECK(mesh.triangles == std::vector<Vec3ui>{{0, 1, 2}, {2, 1, 0}});
}

TEST_CASE("triangle mesh: identical points merge with +0 and -0 alike", "[mesh]")
{
    TriangleMesh mesh;
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {-0.0f, 0, 0}, {0, 0, 1}};
    mesh.triangles = {{0, 1, 2}, {4, 3, 5}};
    mergeIdenticalPoints(mesh);
    CHECK(mesh.points.size() == 4);
    CHECK(mesh.triangles == std::vector<Vec3ui>{{0, 1, 2}, {0, 1, 3}});
}

TEST_CASE("triangle mesh: topology tells closed solids from open or misoriented ones", "[mesh]")
{
    TriangleMesh box = makeBox({});
    CHECK(analyzeTopology(box).isClosed());
    CHECK(signedVolume(box) == Approx(8.0));

    TriangleMesh open = box;
    open.triangles.pop_back();
    CHECK(analyzeTopology(open).boundaryEdges == 3);

    TriangleMesh flipped = box;
    std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
    CHECK(analyzeTopology(flipped).misorientedEdges == 3);
}

TEST_CASE("triangle mesh: transform and append keep the triangles' points", "[mesh]")
{
    TriangleMesh a = makeBox({}), b = makeBox({});
    Mat4d shift = Mat4d::identity();
    shift.setTranslation(Vec3d(10, 0, 0));
    b.transform(shift);
    a.append(b);
    CHECK(a.triangleCount() == 24);
    CHECK(a.bounds().max() == Vec3d(11, 1, 1));
    CHECK(a.bounds().min() == Vec3d(-1, -1, -1));
}
