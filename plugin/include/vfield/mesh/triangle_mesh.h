#pragma once
/// @file triangle_mesh.h
/// An indexed triangle mesh in object space: the common currency of the mesh
/// stage. Triangles are counter-clockwise seen from outside, so the normal
/// (b - a) x (c - a) points out of a closed solid. The layout (Vec3s points,
/// Vec3I triangles) is what OpenVDB's meshToLevelSet takes.

#include <vfield/core/math.h>

#include <cstddef>
#include <vector>

namespace vfield {

struct TriangleMesh {
    std::vector<Vec3f> points;
    std::vector<Vec3ui> triangles;

    std::size_t triangleCount() const { return triangles.size(); }
    bool empty() const { return triangles.empty(); }

    /// Box of the points that triangles use (empty box for an empty mesh).
    BBoxd bounds() const;
    /// (b - a) x (c - a) in double precision: twice the area, along the normal.
    Vec3d areaVector(std::size_t triangle) const;
    Vec3d centroid(std::size_t triangle) const;

    /// Appends another mesh (its indices shifted).
    void append(const TriangleMesh& other);
    /// Applies an affine transform to every point.
    void transform(const Mat4d& worldFromObject);
};

/// Per-point unit normals for smooth shading: the area-weighted sum of the
/// normals of the triangles around each point (zero for unused points).
std::vector<Vec3f> vertexNormals(const TriangleMesh& mesh);

/// Removes triangles of zero area (repeated or collinear corners) and returns
/// how many were removed. Unused points are kept.
std::size_t removeDegenerateTriangles(TriangleMesh& mesh);

/// Merges points with bit-identical coordinates (so +0 and -0 agree) and
/// re-indexes the triangles; the first occurrence of a point keeps its order.
void mergeIdenticalPoints(TriangleMesh& mesh);

/// Edge structure of a mesh: whether it bounds a solid with a defined inside.
/// Solids that touch along an edge (an airplane's wing and fuselage sharing
/// vertices) still bound one: each edge is traversed as often one way as
/// the other, four triangles round it instead of two.
struct MeshTopology {
    std::size_t boundaryEdges = 0;    ///< edges used by an odd number of triangles (holes)
    std::size_t nonManifoldEdges = 0; ///< edges used by three or more triangles
    std::size_t misorientedEdges = 0; ///< edges used an even number of times, more often one way than the other
    bool isClosed() const { return boundaryEdges == 0 && misorientedEdges == 0; }
};
MeshTopology analyzeTopology(const TriangleMesh& mesh);

/// What orientClosedPiecesOutward changed.
struct OrientationRepair {
    std::size_t trianglesFlipped = 0; ///< turned to agree with their neighbours
    std::size_t piecesTurnedOut = 0;  ///< closed pieces that were inside out (negative volume)
    bool changed() const { return trianglesFlipped > 0 || piecesTurnedOut > 0; }
};

/// Orients every closed piece of the mesh outward, as the field needs it:
/// pieces are the sets of triangles joined by edges that two triangles share;
/// a piece with no hole and no edge of three or more triangles is closed. In
/// a closed piece, triangles that traverse a shared edge the same way as their
/// neighbour are flipped (the fewer of the two windings is flipped), and the
/// whole piece is turned around if its signed volume is negative. Open pieces
/// (height fields, single sheets) keep their winding: they have no inside to
/// tell outward by.
OrientationRepair orientClosedPiecesOutward(TriangleMesh& mesh);

/// Signed volume by the divergence theorem: positive for a closed mesh whose
/// normals point outward.
double signedVolume(const TriangleMesh& mesh);

} // namespace vfield
