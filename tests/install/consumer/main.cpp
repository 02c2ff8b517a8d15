// Uses the installed libvfield through its C++ headers: the repulsive field of a
// sphere, and the library's version. Prints "ok" and exits 0 when every check
// holds; names the first that fails and exits 1 otherwise. Built through
// find_package(vfield) (consumer/CMakeLists.txt) and through pkg-config.

#include <vfield/field/octree_field.h>
#include <vfield/host/versions.h>
#include <vfield/mesh/procedural.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace {

bool check(bool holds, const char* what)
{
    if (!holds) std::fprintf(stderr, "consumer: %s does not hold\n", what);
    return holds;
}

} // namespace

int main()
{
    // An icosphere and its octree are mirror images under x -> -x, and so is
    // the field at two points that lie inside cells on both sides: it pushes out
    // of the sphere along +x on one side, along -x on the other, alike in y and
    // z. Beyond the root cube (side 2.4 with the default 10% margin) it is zero.
    const vfield::OctreeField field = vfield::OctreeField::build(vfield::makeSphere({}));
    const vfield::FieldSample right = field.sample({1.1, 0.0, 0.0}), left = field.sample({-1.1, 0.0, 0.0});
    const vfield::FieldSample outside = field.sample({10.0, 0.0, 0.0});
    const vfield::Versions versions = vfield::versions();

    const bool ok = check(right.level >= 1 && right.force[0] > 0.0f, "the field pushes out along +x at (1.1, 0, 0)") &&
                    check(std::abs(right.force[1]) < right.force[0] && std::abs(right.force[2]) < right.force[0],
                          "the push at (1.1, 0, 0) is mostly along x") &&
                    check((vfield::Vec3f(-right.force[0], right.force[1], right.force[2]) - left.force).length() <
                              1e-5f * right.force.length(),
                          "the field at (-1.1, 0, 0) mirrors that at (1.1, 0, 0)") &&
                    check(outside.level == 0 && outside.force.length() == 0.0f, "the field is zero outside its root") &&
                    check(versions.vfield == VFIELD_PACKAGE_VERSION, "the library's version is the package's");
    if (!ok) return 1;
    std::printf("ok: vfield %s, force at (1.1, 0, 0) (%g, %g, %g), level %d\n", versions.vfield.c_str(), right.force[0],
                right.force[1], right.force[2], right.level);
    return 0;
}
