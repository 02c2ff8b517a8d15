#include <vfield/field/triangle_box_overlap.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

/// Do the projections of the triangle (p0, p1, p2 already projected) and of a
/// box of half size `radius` on the same axis stay apart?
bool separated(double p0, double p1, double p2, double radius)
{
    const double lo = std::min({p0, p1, p2}), hi = std::max({p0, p1, p2});
    return lo > radius || hi < -radius;
}

} // namespace

bool triangleOverlapsBox(const Vec3d& boxCenter, const Vec3d& h, const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    // Work in the box's frame.
    const Vec3d v[3] = {a - boxCenter, b - boxCenter, c - boxCenter};
    const Vec3d e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};

    // The three box normals: the triangle's bounding box against the box.
    for (int axis = 0; axis < 3; ++axis)
        if (separated(v[0][axis], v[1][axis], v[2][axis], h[axis])) return false;

    // The nine axes edge_i x unit_j. For axis = e x unit_x = (0, e.z, -e.y):
    // projection p = v.y * e.z - v.z * e.y, box radius = h.y |e.z| + h.z |e.y|.
    for (const Vec3d& edge : e) {
        for (int j = 0; j < 3; ++j) {
            const int k = (j + 1) % 3, l = (j + 2) % 3;
            const double p[3] = {v[0][k] * edge[l] - v[0][l] * edge[k], v[1][k] * edge[l] - v[1][l] * edge[k],
                                 v[2][k] * edge[l] - v[2][l] * edge[k]};
            const double radius = h[k] * std::abs(edge[l]) + h[l] * std::abs(edge[k]);
            if (separated(p[0], p[1], p[2], radius)) return false;
        }
    }

    // The triangle's plane against the box.
    const Vec3d normal = e[0].cross(e[1]);
    const double distance = normal.dot(v[0]);
    const double radius = h[0] * std::abs(normal[0]) + h[1] * std::abs(normal[1]) + h[2] * std::abs(normal[2]);
    return std::abs(distance) <= radius;
}

} // namespace vfield
