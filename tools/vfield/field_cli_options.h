#pragma once
// The mesh and octree options that probe, bake-field and field-slice share:
// a mesh file with the octree's options as flags, or a scene's object with
// its own repulsion settings (the flags then change them, as --set would).

#include "command.h"
#include "declared_flags.h"

#include <vfield/field/octree_field.h>
#include <vfield/mesh/triangle_mesh.h>

#include <optional>
#include <string>

namespace vfield::cli {

struct FieldCliOptions {
    std::string meshPath;
    std::string scenePath, objectName;
    DeclaredFlags octreeFlags;       ///< OctreeFieldSettings' keys as flags (--margin, --max-level, ...)
    DeclaredFlags meshFlags;         ///< MeshSettings's (--tessellate)
    std::optional<double> maxMemory; ///< bytes (--max-memory)
};

/// Declares MESH, --scene and --object, and the octree's flags.
void addFieldOptions(CLI::App& command, FieldCliOptions& options);

struct MeshAndField {
    TriangleMesh mesh;
    OctreeField field;
};

/// Loads or makes the mesh (object space), builds its octree field, logs a summary.
MeshAndField loadMeshAndBuildField(const FieldCliOptions& options, const GlobalOptions& global);

} // namespace vfield::cli
