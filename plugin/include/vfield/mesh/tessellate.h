#pragma once
/// @file tessellate.h
/// TriangleMesh -> finer TriangleMesh of about uniform triangle size: the
/// paper's optional preparation step that spreads triangles evenly over the
/// octree. Shape and orientation are kept, and a closed mesh stays closed:
/// edges are split at their midpoints, shared between neighbours.

#include <vfield/mesh/triangle_mesh.h>

#include <cstddef>

namespace vfield {

/// Splits edges until none is longer than maxEdgeLength (world units, > 0).
/// Throws ValueError if the result would exceed maxTriangles.
TriangleMesh tessellate(const TriangleMesh& mesh, double maxEdgeLength, std::size_t maxTriangles = 50'000'000);

} // namespace vfield
