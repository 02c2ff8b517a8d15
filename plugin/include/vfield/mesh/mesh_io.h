#pragma once
/// @file mesh_io.h
/// Mesh files -> TriangleMesh (object space, the file's own units), and back.
/// Reading goes through assimp (OBJ, PLY, STL, glTF/GLB and the rest of its
/// formats): every mesh of the file, placed by its node transforms, quads and
/// n-gons triangulated, identical points merged, zero-area triangles dropped.

#include <vfield/mesh/triangle_mesh.h>

#include <cstddef>
#include <string>
#include <vector>

namespace vfield {

/// What loading found and repaired besides the mesh, for the caller's log.
struct MeshLoadReport {
    std::size_t degenerateTrianglesRemoved = 0; ///< zero-area triangles dropped
    std::size_t nonTriangleFacesIgnored = 0;    ///< points and lines in the file
    OrientationRepair orientation;              ///< closed pieces turned outward (orientClosedPiecesOutward)

    /// One line per finding, each naming the file ("a.obj: ..."); the
    /// orientation's is a warning, since it changes which way the field pushes.
    std::vector<std::string> lines(const std::string& path) const;
};

/// Reads a mesh file; closed pieces are oriented outward (an inside-out
/// mesh would attract instead of repel). Throws FileError ("<path>: <problem>") for a missing,
/// unreadable, empty, malformed or non-finite file, or one with no triangle of
/// non-zero area.
TriangleMesh loadMesh(const std::string& path, MeshLoadReport* report = nullptr);

/// Writes a Wavefront OBJ (points and triangles, 1-based indices) atomically.
void saveObj(const TriangleMesh& mesh, const std::string& path);

} // namespace vfield
