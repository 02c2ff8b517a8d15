#include <vfield/mesh/mesh_source.h>

#include <vfield/core/field_visitors.h>
#include <vfield/mesh/tessellate.h>

#include <filesystem>

namespace vfield {

void MeshSource::validate() const { checkFields(*this); }

TriangleMesh makeMesh(const MeshSource& source, MeshLoadReport* report)
{
    source.validate();
    TriangleMesh mesh;
    switch (source.kind) {
    case MeshSource::Kind::File:
        mesh = loadMesh(source.path, report);
        break;
    case MeshSource::Kind::Terrain:
        mesh = makeTerrain(source.terrain);
        break;
    case MeshSource::Kind::Heightmap:
        mesh = makeHeightmapTerrain(source.heightmap);
        break;
    case MeshSource::Kind::Sphere:
        mesh = makeSphere(source.sphere);
        break;
    case MeshSource::Kind::Box:
        mesh = makeBox(source.box);
        break;
    }
    if (source.tessellateEdge > 0) mesh = tessellate(mesh, source.tessellateEdge);
    return mesh;
}

} // namespace vfield
