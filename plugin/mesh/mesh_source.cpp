#include <vfield/mesh/mesh_source.h>

#include <vfield/core/field_visitors.h>
#include <vfield/mesh/tessellate.h>

#include <filesystem>

namespace vfield {

void MeshSettings::validate() const { checkFields(*this); }

TriangleMesh makeMesh(const MeshSettings& source, MeshLoadReport* report)
{
    source.validate();
    TriangleMesh mesh;
    switch (source.kind) {
    case MeshSettings::Kind::File:
        mesh = loadMesh(source.path, report);
        break;
    case MeshSettings::Kind::Terrain:
        mesh = makeTerrain(source.terrain);
        break;
    case MeshSettings::Kind::Heightmap:
        mesh = makeHeightmapTerrain(source.heightmap);
        break;
    case MeshSettings::Kind::Sphere:
        mesh = makeSphere(source.sphere);
        break;
    case MeshSettings::Kind::Box:
        mesh = makeBox(source.box);
        break;
    }
    if (source.tessellateEdge > 0) mesh = tessellate(mesh, source.tessellateEdge);
    return mesh;
}

} // namespace vfield
