#include <vfield/mesh/triangle_mesh.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <unordered_map>

namespace vfield {

BBoxd TriangleMesh::bounds() const
{
    BBoxd box; // default-constructed BBox is empty (min > max)
    for (const Vec3ui& t : triangles)
        for (int corner = 0; corner < 3; ++corner) box.expand(Vec3d(points[t[corner]]));
    return box;
}

Vec3d TriangleMesh::areaVector(std::size_t triangle) const
{
    const Vec3ui& t = triangles[triangle];
    const Vec3d a(points[t[0]]), b(points[t[1]]), c(points[t[2]]);
    return (b - a).cross(c - a);
}

Vec3d TriangleMesh::centroid(std::size_t triangle) const
{
    const Vec3ui& t = triangles[triangle];
    return (Vec3d(points[t[0]]) + Vec3d(points[t[1]]) + Vec3d(points[t[2]])) / 3.0;
}

void TriangleMesh::append(const TriangleMesh& other)
{
    const auto offset = static_cast<uint32_t>(points.size());
    points.insert(points.end(), other.points.begin(), other.points.end());
    triangles.reserve(triangles.size() + other.triangles.size());
    for (const Vec3ui& t : other.triangles) triangles.emplace_back(t[0] + offset, t[1] + offset, t[2] + offset);
}

void TriangleMesh::transform(const Mat4d& worldFromObject)
{
    for (Vec3f& p : points) p = Vec3f(worldFromObject.transform(Vec3d(p)));
}

std::vector<Vec3f> vertexNormals(const TriangleMesh& mesh)
{
    std::vector<Vec3d> sum(mesh.points.size(), Vec3d(0.0));
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
        const Vec3d area = mesh.areaVector(t);
        for (int corner = 0; corner < 3; ++corner) sum[mesh.triangles[t][corner]] += area;
    }
    std::vector<Vec3f> normals(sum.size());
    for (std::size_t i = 0; i < sum.size(); ++i) normals[i] = Vec3f(sum[i].unitSafe());
    return normals;
}

std::size_t removeDegenerateTriangles(TriangleMesh& mesh)
{
    const std::size_t before = mesh.triangles.size();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < before; ++i) {
        if (mesh.areaVector(i).lengthSqr() > 0.0) mesh.triangles[kept++] = mesh.triangles[i];
    }
    mesh.triangles.resize(kept);
    return before - kept;
}

namespace {

struct PointKey {
    uint32_t bits[3];
    bool operator==(const PointKey& o) const { return std::memcmp(bits, o.bits, sizeof bits) == 0; }
};

struct PointKeyHash {
    std::size_t operator()(const PointKey& k) const
    {
        uint64_t h = 1469598103934665603ull;
        for (uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
        return static_cast<std::size_t>(h);
    }
};

PointKey keyOf(const Vec3f& p)
{
    PointKey key;
    for (int i = 0; i < 3; ++i) {
        const float v = p[i] + 0.0f; // -0 becomes +0
        std::memcpy(&key.bits[i], &v, sizeof v);
    }
    return key;
}

} // namespace

void mergeIdenticalPoints(TriangleMesh& mesh)
{
    std::unordered_map<PointKey, uint32_t, PointKeyHash> indexOf;
    indexOf.reserve(mesh.points.size());
    std::vector<uint32_t> remap(mesh.points.size());
    std::vector<Vec3f> merged;
    merged.reserve(mesh.points.size());
    for (std::size_t i = 0; i < mesh.points.size(); ++i) {
        const auto [it, inserted] = indexOf.emplace(keyOf(mesh.points[i]), static_cast<uint32_t>(merged.size()));
        if (inserted) merged.push_back(mesh.points[i]);
        remap[i] = it->second;
    }
    for (Vec3ui& t : mesh.triangles)
        for (int corner = 0; corner < 3; ++corner) t[corner] = remap[t[corner]];
    mesh.points = std::move(merged);
}

MeshTopology analyzeTopology(const TriangleMesh& mesh)
{
    // Each undirected edge counts its uses and the balance of its directions:
    // in a closed, consistently wound mesh every edge is used twice, once each way.
    struct EdgeUse {
        int count = 0;
        int balance = 0;
    };
    std::unordered_map<uint64_t, EdgeUse> edges;
    edges.reserve(mesh.triangles.size() * 2);
    for (const Vec3ui& t : mesh.triangles) {
        for (int corner = 0; corner < 3; ++corner) {
            const uint32_t a = t[corner], b = t[(corner + 1) % 3];
            const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            EdgeUse& use = edges[key];
            ++use.count;
            use.balance += a < b ? 1 : -1;
        }
    }
    MeshTopology topology;
    for (const auto& [key, use] : edges) {
        if (use.count == 1) ++topology.boundaryEdges;
        else if (use.count > 2) ++topology.nonManifoldEdges;
        else if (use.balance != 0) ++topology.misorientedEdges;
    }
    return topology;
}

double signedVolume(const TriangleMesh& mesh)
{
    double sixTimesVolume = 0.0;
    for (const Vec3ui& t : mesh.triangles) {
        const Vec3d a(mesh.points[t[0]]), b(mesh.points[t[1]]), c(mesh.points[t[2]]);
        sixTimesVolume += a.dot(b.cross(c));
    }
    return sixTimesVolume / 6.0;
}

} // namespace vfield
