#include <vfield/mesh/tessellate.h>

#include <vfield/core/error.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

namespace vfield {

namespace {

uint64_t edgeKey(uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); }

/// One round of red-green refinement: every edge longer than the limit is cut
/// at its midpoint (one new point per edge, shared by both its triangles), and
/// each triangle is split into 2, 3 or 4 according to how many of its edges
/// were cut. Returns false when nothing was cut.
bool refineOnce(TriangleMesh& mesh, double maxLengthSqr)
{
    std::unordered_map<uint64_t, uint32_t> midpointOf;
    const auto midpoint = [&](uint32_t a, uint32_t b) -> int64_t {
        const Vec3d pa(mesh.points[a]), pb(mesh.points[b]);
        if ((pb - pa).lengthSqr() <= maxLengthSqr) return -1;
        const auto [it, inserted] = midpointOf.emplace(edgeKey(a, b), uint32_t(mesh.points.size()));
        if (inserted) mesh.points.emplace_back((pa + pb) * 0.5);
        return it->second;
    };
    const auto distanceSqr = [&](uint32_t a, uint32_t b) { return (Vec3d(mesh.points[a]) - Vec3d(mesh.points[b])).lengthSqr(); };

    std::vector<Vec3ui> refined;
    refined.reserve(mesh.triangles.size() * 2);
    bool anyCut = false;
    for (const Vec3ui& t : mesh.triangles) {
        const int64_t cut[3] = {midpoint(t[0], t[1]), midpoint(t[1], t[2]), midpoint(t[2], t[0])};
        const int cuts = int(cut[0] >= 0) + int(cut[1] >= 0) + int(cut[2] >= 0);
        if (cuts == 0) {
            refined.push_back(t);
            continue;
        }
        anyCut = true;
        if (cuts == 3) {
            const auto ab = uint32_t(cut[0]), bc = uint32_t(cut[1]), ca = uint32_t(cut[2]);
            refined.emplace_back(t[0], ab, ca);
            refined.emplace_back(t[1], bc, ab);
            refined.emplace_back(t[2], ca, bc);
            refined.emplace_back(ab, bc, ca);
            continue;
        }
        // Rotate the corners (keeping their cyclic order, hence the orientation)
        // so that edge (a, b) is cut, and with two cuts (b, c) is the other one.
        int r = 0;
        if (cuts == 1) r = cut[0] >= 0 ? 0 : cut[1] >= 0 ? 1 : 2;
        else r = cut[2] < 0 ? 0 : cut[0] < 0 ? 1 : 2;
        const uint32_t a = t[r], b = t[(r + 1) % 3], c = t[(r + 2) % 3];
        const auto mab = uint32_t(cut[r]);
        if (cuts == 1) {
            refined.emplace_back(a, mab, c);
            refined.emplace_back(mab, b, c);
        } else {
            const auto mbc = uint32_t(cut[(r + 1) % 3]);
            refined.emplace_back(mab, b, mbc);
            // The quad (a, mab, mbc, c) is split along its shorter diagonal.
            if (distanceSqr(a, mbc) <= distanceSqr(mab, c)) {
                refined.emplace_back(a, mab, mbc);
                refined.emplace_back(a, mbc, c);
            } else {
                refined.emplace_back(a, mab, c);
                refined.emplace_back(mab, mbc, c);
            }
        }
    }
    mesh.triangles = std::move(refined);
    return anyCut;
}

} // namespace

TriangleMesh tessellate(const TriangleMesh& mesh, double maxEdgeLength, std::size_t maxTriangles)
{
    if (!(maxEdgeLength > 0)) throw ValueError("tessellation edge length must be positive");

    // Each triangle ends up with about (longest edge / limit)^2 pieces: refuse
    // an absurd request before allocating it.
    double expected = 0;
    for (const Vec3ui& t : mesh.triangles) {
        double longest = 0;
        for (int corner = 0; corner < 3; ++corner)
            longest = std::max(longest, (Vec3d(mesh.points[t[corner]]) - Vec3d(mesh.points[t[(corner + 1) % 3]])).length());
        expected += std::max(1.0, std::pow(longest / maxEdgeLength, 2.0));
    }
    if (expected > double(maxTriangles))
        throw ValueError("tessellation to edges of " + std::to_string(maxEdgeLength) + " would make about " +
                         std::to_string(uint64_t(expected)) + " triangles (limit " + std::to_string(maxTriangles) + ")");

    TriangleMesh result = mesh;
    const double maxLengthSqr = maxEdgeLength * maxEdgeLength;
    while (refineOnce(result, maxLengthSqr)) {
        if (result.triangles.size() > 4 * maxTriangles)
            throw ValueError("tessellation exceeded " + std::to_string(4 * maxTriangles) + " triangles");
    }
    return result;
}

} // namespace vfield
