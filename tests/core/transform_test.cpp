// Object-to-world transforms: rotations, inverses and matrices agree.

#include <vfield/core/transform.h>

#include <catch2/catch.hpp>

using namespace vfield;

TEST_CASE("transform: 90 degrees about y turns +x into -z", "[sim]")
{
    const Quatd q = Transform::rotationFromDegrees({0, 90, 0});
    const Vec3d v = rotate(q, {1, 0, 0});
    CHECK(v[0] == Approx(0).margin(1e-12));
    CHECK(v[2] == Approx(-1).margin(1e-12));
    Transform t;
    t.rotation = q;
    t.translation = Vec3d(1, 2, 3);
    t.scale = 2.0;
    const Vec3d p(0.3, -0.2, 0.7);
    CHECK((t.objectFromWorld(t.worldFromObject(p)) - p).length() < 1e-12);
    CHECK((t.matrix().transform(p) - t.worldFromObject(p)).length() < 1e-12);
}
