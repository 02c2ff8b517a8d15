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
    // in a closed, consistently wound mesh every edge is used as often one way
    // as the other (twice, or four times where two solids touch along it).
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
        if (use.count > 2) ++topology.nonManifoldEdges;
        if (use.count % 2 == 1) ++topology.boundaryEdges;
        else if (use.balance != 0) ++topology.misorientedEdges;
    }
    return topology;
}

OrientationRepair orientClosedPiecesOutward(TriangleMesh& mesh)
{
    // Every undirected edge and the triangles that use it.
    const std::size_t n = mesh.triangles.size();
    std::unordered_map<uint64_t, std::vector<uint32_t>> users;
    users.reserve(n * 2);
    const auto edgeKey = [](uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
    for (uint32_t t = 0; t < n; ++t)
        for (int corner = 0; corner < 3; ++corner)
            users[edgeKey(mesh.triangles[t][corner], mesh.triangles[t][(corner + 1) % 3])].push_back(t);
    // Whether triangle t traverses the edge a -> b (rather than b -> a).
    const auto traverses = [&](uint32_t t, uint32_t a, uint32_t b) {
        const Vec3ui& v = mesh.triangles[t];
        for (int corner = 0; corner < 3; ++corner)
            if (v[corner] == a && v[(corner + 1) % 3] == b) return true;
        return false;
    };

    OrientationRepair repair;
    std::vector<int8_t> flip(n, -1); // per triangle: -1 unvisited, else whether it is flipped relative to its piece's seed
    std::vector<uint32_t> piece, queue;
    for (uint32_t seed = 0; seed < n; ++seed) {
        if (flip[seed] >= 0) continue;
        // Walk the piece across shared edges, choosing each triangle's winding
        // to traverse the edge opposite to its already-placed neighbour.
        piece.clear();
        queue.assign(1, seed);
        flip[seed] = 0;
        bool closed = true;
        while (!queue.empty()) {
            const uint32_t t = queue.back();
            queue.pop_back();
            piece.push_back(t);
            for (int corner = 0; corner < 3; ++corner) {
                const uint32_t a = mesh.triangles[t][corner], b = mesh.triangles[t][(corner + 1) % 3];
                const std::vector<uint32_t>& around = users[edgeKey(a, b)];
                if (around.size() != 2) {
                    closed = false;
                    continue;
                }
                const uint32_t other = around[0] == t ? around[1] : around[0];
                if (flip[other] >= 0) continue;
                // As stored, t runs a -> b; with flips applied they must run opposite ways.
                const bool sameWay = traverses(other, a, b);
                flip[other] = int8_t(sameWay != bool(flip[t]));
                queue.push_back(other);
            }
        }
        if (!closed) {
            for (const uint32_t t : piece) flip[t] = 0;
            continue;
        }
        // The consistent winding closer to the file's, then outward.
        std::size_t flipped = 0;
        for (const uint32_t t : piece) flipped += std::size_t(flip[t]);
        const bool invert = 2 * flipped > piece.size();
        double sixTimesVolume = 0.0;
        for (const uint32_t t : piece) {
            const Vec3ui& v = mesh.triangles[t];
            const double sign = bool(flip[t]) != invert ? -1.0 : 1.0;
            sixTimesVolume += sign * Vec3d(mesh.points[v[0]]).dot(Vec3d(mesh.points[v[1]]).cross(Vec3d(mesh.points[v[2]])));
        }
        const bool turnOut = sixTimesVolume < 0.0;
        repair.trianglesFlipped += invert ? piece.size() - flipped : flipped;
        repair.piecesTurnedOut += turnOut;
        for (const uint32_t t : piece) {
            if ((bool(flip[t]) != invert) != turnOut) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
            flip[t] = 0;
        }
    }
    return repair;
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
