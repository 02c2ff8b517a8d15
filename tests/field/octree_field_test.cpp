#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/field/octree_field.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/mesh/procedural.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <set>

using namespace vfield;
using Catch::Matchers::WithinAbs;

namespace {

void requireForce(const FieldSample& s, const Vec3d& expected, int level, bool isSurface)
{
    INFO("force (" << s.force[0] << ", " << s.force[1] << ", " << s.force[2] << ") level " << s.level);
    CHECK(s.level == level);
    CHECK(s.isSurface == isSurface);
    for (int axis = 0; axis < 3; ++axis) CHECK_THAT(s.force[axis], WithinAbs(expected[axis], 1e-5));
}

TriangleMesh singleTriangle()
{
    TriangleMesh mesh;
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.triangles = {{0, 1, 2}}; // normal +z
    return mesh;
}

OctreeFieldSettings withMargin(double margin)
{
    OctreeFieldSettings options;
    options.margin = margin;
    return options;
}

} // namespace

TEST_CASE("octree field: root is a cube around the mesh with 10% dead space by default", "[field]")
{
    // Bounding box [0,1] x [0,1] x [0,0]: side 1 + 2 x 0.1, centred on (0.5, 0.5, 0).
    const OctreeField field = OctreeField::build(singleTriangle());
    CHECK_THAT(field.rootSide(), WithinAbs(1.2, 1e-12));
    CHECK_THAT(field.bounds().min()[0], WithinAbs(-0.1, 1e-12));
    CHECK_THAT(field.bounds().min()[2], WithinAbs(-0.6, 1e-12));
    CHECK_THAT(field.bounds().max()[1], WithinAbs(1.1, 1e-12));

    const OctreeField wide = OctreeField::build(singleTriangle(), withMargin(2.0));
    CHECK_THAT(wide.rootSide(), WithinAbs(5.0, 1e-12));
}

TEST_CASE("octree field: a single triangle makes a root leaf with the boosted normal", "[field]")
{
    const OctreeField field = OctreeField::build(singleTriangle());
    CHECK(field.depth() == 1);
    CHECK(field.leafCount() == 1);
    // strength 1 x level 1 x surface boost 10, along the normal.
    requireForce(field.sample({0.9, 0.9, 0.5}), {0, 0, 10}, 1, true);
}

TEST_CASE("octree field: magnitude is strength x level x surface boost", "[field]")
{
    OctreeFieldSettings options;
    options.strength = 2.5;
    options.surfaceBoost = 4.0;
    const OctreeField field = OctreeField::build(singleTriangle(), options);
    requireForce(field.sample({0.2, 0.2, 0.0}), {0, 0, 10}, 1, true);
    CHECK(field.magnitude(3, false) == 7.5);
    CHECK(field.magnitude(3, true) == 30.0);
}

TEST_CASE("octree field: a doubling growth makes each level twice as strong as its parent", "[field]")
{
    // The plane of the test below: leaves at every level from 3 to 6.
    TriangleMesh plane;
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j) test::addSquareFacingUp(plane, i, j, i + 1, j + 1, 0.37);
    OctreeFieldSettings options;
    options.maxLevel = 6;
    options.strength = 0.5;
    options.surfaceBoost = 3.0;
    options.growth = MagnitudeGrowth::Doubling;
    const OctreeField field = OctreeField::build(plane, options);
    std::set<int> levels;
    for (const FieldLeaf& leaf : field.leaves()) {
        levels.insert(leaf.level);
        const double expected = 0.5 * std::ldexp(1.0, leaf.level - 1) * (leaf.isSurface ? 3.0 : 1.0);
        CHECK(double(leaf.force.length()) == Approx(expected).epsilon(1e-6));
    }
    CHECK(levels.size() >= 4);
    CHECK(field.magnitude(6, false) == 16.0);
    CHECK(magnitudeAtLevel(MagnitudeGrowth::Linear, 0.5, 6.0) == 3.0);
    CHECK(magnitudeAtLevel(MagnitudeGrowth::Doubling, 0.5, 2.5) == Approx(0.5 * std::sqrt(8.0)));
}

TEST_CASE("octree field: outside the root the force is zero and the level 0", "[field]")
{
    const OctreeField field = OctreeField::build(singleTriangle());
    requireForce(field.sample({1.1000001, 0.5, 0.0}), {0, 0, 0}, 0, false);
    requireForce(field.sample({0.5, 0.5, -0.61}), {0, 0, 0}, 0, false);
    requireForce(field.sample({NAN, 0.5, 0.0}), {0, 0, 0}, 0, false);
}

TEST_CASE("octree field: a cube's octants hold their three faces and point along the diagonal", "[field]")
{
    // The cube [-1,1]^3 with no margin is its own root; 12 triangles > 6 split
    // it once. Each octant's closed box touches both triangles of three faces:
    // average normal (1,1,1)/sqrt(3) in the (+,+,+) octant, level 2, boosted.
    const OctreeField field = OctreeField::build(makeBox({}), withMargin(0.0));
    CHECK(field.depth() == 2);
    CHECK(field.leafCount() == 8);
    const double m = 2 * 10 / std::sqrt(3.0);
    requireForce(field.sample({0.5, 0.5, 0.5}), {m, m, m}, 2, true);
    requireForce(field.sample({-0.5, 0.5, -0.5}), {-m, m, -m}, 2, true);
    requireForce(field.sample({-0.5, -0.5, -0.5}), {-m, -m, -m}, 2, true);
}

TEST_CASE("octree field: cells are half-open but closed on the root's max faces", "[field]")
{
    const OctreeField field = OctreeField::build(makeBox({}), withMargin(0.0));
    const double m = 2 * 10 / std::sqrt(3.0);
    requireForce(field.sample({0, 0, 0}), {m, m, m}, 2, true);       // the centre belongs to the upper octant
    requireForce(field.sample({1, 1, 1}), {m, m, m}, 2, true);       // the root's max corner is inside
    requireForce(field.sample({-1, -1, -1}), {-m, -m, -m}, 2, true); // and so is its min corner
    requireForce(field.sample({-1e-12, 0, 0}), {-m, m, m}, 2, true);
}

TEST_CASE("octree field: an empty leaf takes its parent's direction as in the paper's figure 3", "[field]")
{
    const OctreeField field = OctreeField::build(test::paperFigure3Mesh(), withMargin(0.25));
    REQUIRE(field.bounds().min() == Vec3d(0.0));
    REQUIRE(field.bounds().max() == Vec3d(4.0));
    CHECK(field.depth() == 3);

    // The (-,-,-) octant holds the 8 upward triangles and splits: its level-3
    // cells with a square point up, boosted; the empty ones above them take the
    // octant's own direction (+z) at level 3.
    requireForce(field.sample({0.5, 0.5, 0.5}), {0, 0, 30}, 3, true);
    requireForce(field.sample({1.5, 0.5, 0.9}), {0, 0, 30}, 3, true);
    requireForce(field.sample({0.5, 0.5, 1.5}), {0, 0, 3}, 3, false);
    requireForce(field.sample({1.5, 1.5, 1.99}), {0, 0, 3}, 3, false);

    // The (+,+,+) octant holds the lone +x triangle.
    requireForce(field.sample({3.5, 3.5, 3.25}), {20, 0, 0}, 2, true);

    // Empty root octants take the root's direction: the average of all nine
    // normals, (8 (0,0,1) + (1,0,0)) / 9, normalized.
    const double s = 2.0 / std::sqrt(65.0);
    requireForce(field.sample({3.0, 1.0, 1.0}), {s, 0, 8 * s}, 2, false);
    requireForce(field.sample({1.0, 3.0, 3.0}), {s, 0, 8 * s}, 2, false);
}

TEST_CASE("octree field (paper rule): a node whose normals cancel takes its parent's direction", "[field]")
{
    // Seven +x triangles in the (+,+,+) octant and a two-sided triangle (both
    // windings) in the (-,-,-) octant: the root's average is +x, the (-,-,-)
    // octant's is zero, so it takes +x.
    TriangleMesh mesh;
    for (int i = 0; i < 7; ++i) {
        const auto base = uint32_t(mesh.points.size());
        const float y = 3.3f + 0.1f * float(i);
        mesh.points.insert(mesh.points.end(), {{4, y, 3}, {4, y + 0.1f, 3}, {4, y + 0.1f, 4}});
        mesh.triangles.emplace_back(base, base + 1, base + 2);
    }
    const auto base = uint32_t(mesh.points.size());
    mesh.points.insert(mesh.points.end(), {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}});
    mesh.triangles.emplace_back(base, base + 1, base + 2);
    mesh.triangles.emplace_back(base, base + 2, base + 1);

    OctreeFieldSettings paper = withMargin(0.0);
    paper.splitRule = SplitRule::Paper;
    const OctreeField field = OctreeField::build(mesh, paper);
    REQUIRE(field.bounds().min() == Vec3d(0.0));
    requireForce(field.sample({0.5, 0.25, 0.5}), {20, 0, 0}, 2, true);
}

TEST_CASE("octree field (paper rule): normals that cancel at the root give zero force", "[field]")
{
    TriangleMesh twoSided = singleTriangle();
    twoSided.triangles.emplace_back(0, 2, 1);
    OctreeFieldSettings paper;
    paper.splitRule = SplitRule::Paper;
    const OctreeField field = OctreeField::build(twoSided, paper);
    requireForce(field.sample({0.5, 0.5, 0.0}), {0, 0, 0}, 1, true);
    // Split by the normal cone down to maxLevel, the two windings stay together and still cancel.
    const OctreeField cone = OctreeField::build(twoSided);
    CHECK(cone.sample({0.5, 0.5, 0.0}).level == OctreeFieldSettings{}.maxLevel);
    CHECK(cone.sample({0.5, 0.5, 0.0}).force == Vec3f(0.0f));
}

TEST_CASE("octree field: the two sides of a thin part push away from it, beyond the paper's rule", "[field]")
{
    // The shipped airplane's wing: just above and just below it. The paper's
    // rule keeps top, bottom and leading edge in one leaf, whose average
    // points forward (+x) on both sides.
    const TriangleMesh airplane = loadMesh(std::string(VFIELD_SCENES_DIR) + "/meshes/airplane.obj");
    const Vec3d above(0.05, 0.2, 3.0), below(0.05, -0.25, 3.0);
    const OctreeField cone = OctreeField::build(airplane);
    CHECK(cone.sample(above).force[1] > 10.0f);
    CHECK(cone.sample(below).force[1] < -10.0f);
    CHECK(std::abs(cone.sample(above).force[0]) < 1e-6f);
    OctreeFieldSettings paper;
    paper.splitRule = SplitRule::Paper;
    const OctreeField paperField = OctreeField::build(airplane, paper);
    CHECK(paperField.sample(above).force == Vec3f(40, 0, 0));
    CHECK(paperField.sample(below).force == Vec3f(40, 0, 0));

    // A thin plate (12 triangles, 0.1 thick) that the count rule never splits.
    OctreeFieldSettings few;
    few.maxPerLeaf = 16;
    const TriangleMesh plate = makeBox({{-2, -0.05, -2}, {2, 0.05, 2}});
    const OctreeField plateField = OctreeField::build(plate, few);
    for (const double x : {-1.3, 0.2, 1.7}) {
        INFO("x " << x);
        CHECK(plateField.sample({x, 0.07, 0.3}).force[1] > 0.0f);
        CHECK(plateField.sample({x, -0.07, 0.3}).force[1] < 0.0f);
    }
}

TEST_CASE("octree field: over a plane every leaf points along its normal and grows with depth", "[field]")
{
    // A 16 x 16 grid of squares in z = 0.37 (512 triangles): the octree
    // refines towards the plane, which lies on the root's central plane and so
    // in the cells on both its sides; every node's average normal is +z.
    const double z = double(0.37f); // as the mesh stores it
    TriangleMesh plane;
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j) test::addSquareFacingUp(plane, i, j, i + 1, j + 1, z);
    OctreeFieldSettings options;
    options.maxLevel = 6;
    const OctreeField field = OctreeField::build(plane, options);
    CHECK(field.depth() == 6);
    for (const FieldLeaf& leaf : field.leaves()) {
        const double expected = leaf.level * (leaf.isSurface ? 10.0 : 1.0);
        CHECK(leaf.force == Vec3f(0.0f, 0.0f, float(expected)));
        // Surface leaves are exactly those whose closed box touches the square.
        const BBoxd& b = leaf.bounds;
        const bool touchesPlane = b.min()[2] <= z && b.max()[2] >= z && b.min()[0] <= 16.0 && b.max()[0] >= 0.0 &&
                                  b.min()[1] <= 16.0 && b.max()[1] >= 0.0;
        CHECK(leaf.isSurface == touchesPlane);
    }
    // The field strengthens towards the plane, alike on both sides: far away
    // an empty level-3 cell; one finest cell (0.6) off the plane an empty level-6 leaf.
    CHECK(field.sample({8, 8, z + 7.0}).level == 3);
    CHECK(field.sample({8, 8, z - 7.0}).level == 3);
    CHECK(field.sample({8, 8, z + 0.9}).level == 6);
    CHECK(field.sample({8, 8, z - 0.9}).level == 6);
    CHECK_FALSE(field.sample({8, 8, z + 0.9}).isSurface);
}

TEST_CASE("octree field: around a sphere the surface force points outward", "[field]")
{
    const TriangleMesh sphere = makeSphere({{0, 0, 0}, 1.0, 3});
    const OctreeField field = OctreeField::build(sphere);
    // A triangle's centroid lies in a leaf that holds the triangle.
    for (std::size_t t = 0; t < sphere.triangleCount(); t += 7) {
        const Vec3d centroid = sphere.centroid(t);
        const FieldSample s = field.sample(centroid);
        INFO("triangle " << t);
        CHECK(s.isSurface);
        CHECK(Vec3d(s.force).unitSafe().dot(centroid.unitSafe()) > 0.9);
    }
}

TEST_CASE("octree field: coincident duplicate triangles stop at the maximum level", "[field]")
{
    TriangleMesh duplicates;
    duplicates.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    duplicates.triangles.assign(200, Vec3ui(0, 1, 2));
    const OctreeField field = OctreeField::build(duplicates);
    CHECK(field.depth() == 8);
    const FieldSample s = field.sample({0.2, 0.2, 0.0});
    CHECK(s.level == 8);
    CHECK(s.force == Vec3f(0, 0, 80));
}

TEST_CASE("octree field: zero-area triangles are ignored and a mesh of only those is refused", "[field]")
{
    TriangleMesh mesh = singleTriangle();
    mesh.points.emplace_back(50, 50, 50);
    mesh.triangles.emplace_back(3, 3, 3); // would widen the root if it counted
    CHECK_THAT(OctreeField::build(mesh).rootSide(), WithinAbs(1.2, 1e-12));

    TriangleMesh degenerate;
    degenerate.points = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
    degenerate.triangles = {{0, 1, 2}};
    CHECK_THROWS_AS(OctreeField::build(degenerate), ValueError);
}

TEST_CASE("octree field: options out of range are refused", "[field]")
{
    OctreeFieldSettings options;
    options.maxPerLeaf = 0;
    CHECK_THROWS_WITH(OctreeField::build(singleTriangle(), options), Catch::Contains("maxPerLeaf"));
    options = {};
    options.maxLevel = 21;
    CHECK_THROWS_WITH(OctreeField::build(singleTriangle(), options), Catch::Contains("maxLevel"));
    options = {};
    options.margin = -1.0;
    CHECK_THROWS_WITH(OctreeField::build(singleTriangle(), options), Catch::Contains("margin"));
    options = {};
    options.surfaceBoost = 0.5;
    CHECK_THROWS_WITH(OctreeField::build(singleTriangle(), options), Catch::Contains("surfaceBoost"));
}

TEST_CASE("octree field: hit test averages hit directions and takes the strongest magnitude", "[field]")
{
    const OctreeField field = OctreeField::build(test::paperFigure3Mesh(), withMargin(0.25));
    // Two centroids in one +z leaf of magnitude 30 (counted twice), one in the
    // +x leaf of magnitude 20, one outside the root (ignored).
    const Vec3d force = field.hitTest({{0.5, 0.5, 0.5}, {0.6, 0.4, 0.5}, {3.5, 3.5, 3.25}, {9, 9, 9}});
    const Vec3d expected = Vec3d(1, 0, 2).unitSafe() * 30.0;
    for (int axis = 0; axis < 3; ++axis) CHECK_THAT(force[axis], WithinAbs(expected[axis], 1e-9));

    CHECK(field.hitTest({{9, 9, 9}, {-1, 0, 0}}) == Vec3d(0.0));
    CHECK(field.hitTest({}) == Vec3d(0.0));
}

TEST_CASE("octree field: the same mesh gives the same leaves on every build", "[field]")
{
    TerrainSettings terrain;
    terrain.cellsX = terrain.cellsZ = 96; // over the parallel threshold
    const TriangleMesh mesh = makeTerrain(terrain);
    const std::vector<FieldLeaf> a = OctreeField::build(mesh).leaves(), b = OctreeField::build(mesh).leaves();
    REQUIRE(a.size() == b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        CHECK(a[i].force == b[i].force);
        CHECK(a[i].level == b[i].level);
    }
}
