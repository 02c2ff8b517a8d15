#pragma once
/// @file mesh_source.h
/// Where a scene object's mesh comes from, as the scene file says it: a mesh
/// file or a procedural generator, optionally tessellated. -> TriangleMesh
/// (object space).

#include <vfield/core/json.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/mesh/procedural.h>

#include <string>

namespace vfield {

struct MeshSource {
    enum class Kind { File, Terrain, Sphere, Box, Heightmap };
    Kind kind = Kind::Box;
    std::string path; ///< Kind::File: the mesh file (resolved against the scene's folder)
    TerrainOptions terrain;
    HeightmapOptions heightmap;
    SphereOptions sphere;
    BoxOptions box;
    double tessellateEdge = 0.0; ///< split edges longer than this, object units (0..1e12); 0: off

    /// Throws OptionError naming the first option out of range ("tessellate",
    /// "terrain/octaves", ...).
    void validate() const;
};

/// {"file": "meshes/plane.obj"} | {"terrain": {...}} | {"heightmap": {...}} | {"sphere": {...}} | {"box": {...}},
/// each with an optional "tessellate": edge length. Relative paths are
/// resolved against baseDir.
MeshSource meshSourceFromJson(const JsonValue& json, const std::string& baseDir);

/// Loads or generates the mesh; zero-area triangles are dropped (counted in report).
TriangleMesh makeMesh(const MeshSource& source, MeshLoadReport* report = nullptr);

} // namespace vfield
