#pragma once
// The mesh and octree options that probe, bake-field and field-slice share.

#include "command.h"

#include <vfield/field/octree_field.h>
#include <vfield/mesh/triangle_mesh.h>

#include <optional>
#include <string>

namespace vfield::cli {

struct FieldCliOptions {
    std::string meshPath;
    double margin = 0.0;
    double tessellateEdge = 0.0;
    OctreeFieldOptions octree;
    std::optional<SplitRule> splitRule;
    std::optional<double> maxMemory; ///< bytes (--max-memory)
    const CLI::App* command = nullptr;
};

/// Declares MESH and the octree options (--margin, --max-per-leaf, ...).
void addFieldOptions(CLI::App& command, FieldCliOptions& options);

struct MeshAndField {
    TriangleMesh mesh;
    OctreeField field;
};

/// Loads (and optionally tessellates) the mesh, builds its field, logs a summary.
MeshAndField loadMeshAndBuildField(const FieldCliOptions& options, const GlobalOptions& global);

} // namespace vfield::cli
