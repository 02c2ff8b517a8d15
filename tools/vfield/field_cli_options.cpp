#include "field_cli_options.h"
#include "cli_values.h"

#include <vfield/core/error.h>
#include <vfield/mesh/mesh_source.h>
#include <vfield/scene/memory_estimate.h>
#include <vfield/scene/scene.h>

#include <chrono>
#include <cstdio>

namespace vfield::cli {

void addFieldOptions(CLI::App& command, FieldCliOptions& o)
{
    CLI::Option* mesh = command.add_option("mesh", o.meshPath, "Mesh file (OBJ, PLY, STL, glTF, ...)");
    CLI::Option* scene = command.add_option("--scene", o.scenePath,
                                            "Instead of MESH: a scene file, whose object --object is drawn with its own "
                                            "repulsion settings (the flags below change them)");
    command.add_option("--object", o.objectName, "With --scene: the object's name")->needs(scene);
    scene->excludes(mesh);
    command.parse_complete_callback([&o] {
        if (o.meshPath.empty() == o.scenePath.empty())
            throw CLI::ValidationError("MESH", "give a mesh file or --scene and --object");
        if (!o.scenePath.empty() && o.objectName.empty()) throw CLI::ValidationError("--object", "--scene needs --object NAME");
        if (o.scenePath.empty()) { // a bad flag is a usage error; a scene's values are checked with the scene
            try {
                o.octreeFlags.read<OctreeFieldSettings>();
                o.meshFlags.read<MeshSettings>({{"file", o.meshPath}});
            } catch (const ValueError& e) {
                throw CLI::ValidationError(e.what());
            }
        }
    });
    o.octreeFlags.addTo<OctreeFieldSettings>(command);
    o.meshFlags.addTo<MeshSettings>(command);
    addMaxMemoryOption(command, o.maxMemory);
}

namespace {

/// The scene's object, with the flags given applied to its keys before the scene is read.
ObjectSettings sceneObject(const FieldCliOptions& o)
{
    const Scene plain = vfield::loadScene(o.scenePath);
    std::size_t index = plain.simulation.objects.size();
    std::string names;
    for (std::size_t i = 0; i < plain.simulation.objects.size(); ++i) {
        if (plain.simulation.objects[i].name == o.objectName) index = i;
        names += (names.empty() ? "" : ", ") + plain.simulation.objects[i].name;
    }
    if (index == plain.simulation.objects.size())
        throw FileError(o.scenePath, "no object named \"" + o.objectName + "\" (its objects: " + names + ")");
    const std::string object = "/objects/" + std::to_string(index);
    std::vector<SceneOverride> overrides;
    for (const auto& [key, value] : o.octreeFlags.values()) overrides.push_back({object + "/repulsion/" + key, value});
    for (const auto& [key, value] : o.meshFlags.values()) overrides.push_back({object + "/mesh/" + key, value});
    ObjectSettings spec = vfield::loadScene(o.scenePath, overrides).simulation.objects[index];
    if (!spec.repulsion) throw FileError(o.scenePath, object + "/repulsion: \"" + o.objectName + "\" has no repulsive field");
    if (spec.repulsion->method != RepulsionMethod::Octree)
        throw FileError(o.scenePath, object + "/repulsion/method: \"" + o.objectName + "\"'s field is made by the " +
                                         enumName(spec.repulsion->method) + " method; this command draws the octree field");
    return spec;
}

} // namespace

MeshAndField loadMeshAndBuildField(const FieldCliOptions& o, const GlobalOptions& global)
{
    MeshSettings source;
    OctreeFieldSettings octree;
    std::string meshName = o.meshPath;
    if (!o.scenePath.empty()) {
        const ObjectSettings object = sceneObject(o);
        source = object.mesh;
        octree = object.repulsion->field;
        meshName = o.scenePath + " (" + o.objectName + ")";
    } else {
        source = o.meshFlags.read<MeshSettings>({{"file", o.meshPath}});
        octree = o.octreeFlags.read<OctreeFieldSettings>();
        // A mesh too large for the machine is refused before it is read.
        if (const std::optional<double> limit = o.maxMemory ? o.maxMemory : availableMemory()) {
            try {
                requireMemoryWithin(estimateMeshFileMemory(o.meshPath), *limit,
                                    o.maxMemory ? "the limit" : "the memory available", "loading it and building its field");
            } catch (const OptionError& e) {
                throw FileError(o.meshPath, e.what());
            }
        }
    }
    MeshLoadReport report;
    TriangleMesh mesh = makeMesh(source, &report);
    for (const std::string& line : report.lines(meshName)) log(global, line);

    const auto start = std::chrono::steady_clock::now();
    OctreeField field = OctreeField::build(mesh, octree);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    char line[256];
    std::snprintf(line, sizeof line, "field: %zu triangles, depth %d, %zu leaves, root side %.6g, built in %.1f ms",
                  mesh.triangleCount(), field.depth(), field.leafCount(), field.rootSide(), ms);
    log(global, line);
    return {std::move(mesh), std::move(field)};
}

} // namespace vfield::cli
