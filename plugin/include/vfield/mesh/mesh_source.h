#pragma once
/// @file mesh_source.h
/// Where a scene object's mesh comes from, as the scene file says it: a mesh
/// file or a procedural generator, optionally tessellated. -> TriangleMesh
/// (object space).

#include <vfield/mesh/mesh_io.h>
#include <vfield/mesh/procedural.h>

#include <string>

namespace vfield {

struct MeshSettings {
    enum class Kind { File, Terrain, Sphere, Box, Heightmap };
    Kind kind = Kind::Box;
    std::string path; ///< Kind::File: resolved against the scene's folder
    TerrainSettings terrain;
    HeightmapSettings heightmap;
    SphereSettings sphere;
    BoxSettings box;
    double tessellateEdge = 0.0;

    /// Throws OptionError naming the first option out of range ("tessellate",
    /// "terrain/octaves", ...).
    void validate() const;

    /// {"file": "meshes/plane.obj"} | {"terrain": {...}} | {"heightmap": {...}} | {"sphere": {...}} | {"box": {...}},
    /// each with an optional "tessellate": edge length.
    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("file", self.path)
                  .selects(self.kind, Kind::File)
                  .isPath()
                  .doc("a mesh file (OBJ, PLY, STL, glTF/GLB, ... through assimp), relative to the scene"));
        visit(
            field("terrain", self.terrain).selects(self.kind, Kind::Terrain).doc("a procedural heightfield closed into a solid"));
        visit(
            field("heightmap", self.heightmap).selects(self.kind, Kind::Heightmap).doc("an elevation image closed into a solid"));
        visit(field("sphere", self.sphere).selects(self.kind, Kind::Sphere).doc("an icosphere"));
        visit(field("box", self.box).selects(self.kind, Kind::Box).doc("an axis-aligned box"));
        visit(field("tessellate", self.tessellateEdge)
                  .range(0, 1e12)
                  .unit("object units")
                  .doc("split edges longer than this first; 0: off"));
    }
};

/// Loads or generates the mesh; zero-area triangles are dropped (counted in report).
TriangleMesh makeMesh(const MeshSettings& source, MeshLoadReport* report = nullptr);

} // namespace vfield
