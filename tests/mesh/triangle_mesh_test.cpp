#include <vfield/mesh/mesh_io.h>
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

TEST_CASE("triangle mesh: solids touching along an edge still bound a solid", "[mesh]")
{
    // Two cubes sharing the edge x = y = 1 once their points are merged: four
    // triangles round it, two each way.
    TriangleMesh touching = makeBox({}), second = makeBox({});
    Mat4d shift = Mat4d::identity();
    shift.setTranslation(Vec3d(2, 2, 0));
    second.transform(shift);
    touching.append(second);
    mergeIdenticalPoints(touching);
    const MeshTopology topology = analyzeTopology(touching);
    CHECK(topology.nonManifoldEdges >= 1);
    CHECK(topology.isClosed());

    // The shipped airplane is six closed parts sharing points where they meet.
    const TriangleMesh airplane = loadMesh(std::string(VFIELD_SCENES_DIR) + "/meshes/airplane.obj");
    CHECK(analyzeTopology(airplane).nonManifoldEdges > 0);
    CHECK(analyzeTopology(airplane).isClosed());
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

namespace {

TriangleMesh reversed(TriangleMesh mesh)
{
    for (Vec3ui& t : mesh.triangles) std::swap(t[1], t[2]);
    return mesh;
}

} // namespace

TEST_CASE("triangle mesh: an inside-out closed mesh is turned outward", "[mesh]")
{
    TriangleMesh sphere = reversed(makeSphere({}));
    REQUIRE(signedVolume(sphere) < 0.0);
    const OrientationRepair repair = orientClosedPiecesOutward(sphere);
    CHECK(repair.piecesTurnedOut == 1);
    CHECK(repair.trianglesFlipped == 0);
    CHECK(signedVolume(sphere) > 0.0);
    CHECK(analyzeTopology(sphere).isClosed());
    // An outward mesh is left alone.
    const TriangleMesh before = sphere;
    CHECK_FALSE(orientClosedPiecesOutward(sphere).changed());
    CHECK(sphere.triangles == before.triangles);
}

TEST_CASE("triangle mesh: triangles wound against their neighbours are flipped to agree", "[mesh]")
{
    TriangleMesh sphere = makeSphere({});
    for (const std::size_t t : {3u, 40u, 41u, 200u, 999u}) std::swap(sphere.triangles[t][1], sphere.triangles[t][2]);
    REQUIRE(analyzeTopology(sphere).misorientedEdges > 0);
    const OrientationRepair repair = orientClosedPiecesOutward(sphere);
    CHECK(repair.trianglesFlipped == 5);
    CHECK(repair.piecesTurnedOut == 0);
    CHECK(analyzeTopology(sphere).isClosed());
    CHECK(sphere.triangles == makeSphere({}).triangles);

    // Two pieces, one inside out: each is oriented on its own.
    TriangleMesh two = makeBox({{0, 0, 0}, {1, 1, 1}});
    two.append(reversed(makeBox({{3, 0, 0}, {4, 1, 1}})));
    CHECK(orientClosedPiecesOutward(two).piecesTurnedOut == 1);
    CHECK(signedVolume(two) == Approx(2.0));
}

TEST_CASE("triangle mesh: open meshes keep their winding", "[mesh]")
{
    // A sheet wound downward, and a box with a missing face: no inside to tell outward by.
    TriangleMesh sheet;
    sheet.points = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    sheet.triangles = {{0, 1, 2}, {0, 2, 3}};
    TriangleMesh open = reversed(makeBox({{0, 0, 0}, {1, 1, 1}}));
    open.triangles.pop_back();
    for (TriangleMesh* mesh : {&sheet, &open}) {
        const TriangleMesh before = *mesh;
        CHECK_FALSE(orientClosedPiecesOutward(*mesh).changed());
        CHECK(mesh->triangles == before.triangles);
    }
}
