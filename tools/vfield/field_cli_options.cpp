#include "field_cli_options.h"
#include "cli_values.h"

#include <vfield/core/error.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/mesh/tessellate.h>
#include <vfield/scene/memory_estimate.h>

#include <chrono>
#include <cstdio>

namespace vfield::cli {

void addFieldOptions(CLI::App& command, FieldCliOptions& o)
{
    o.command = &command;
    command.add_option("mesh", o.meshPath, "Mesh file (OBJ, PLY, STL, glTF, ...)")->required();
    command.add_option("--margin", o.margin, "Dead space around the mesh, object units [default: 10% of the largest extent]")
        ->check(CLI::NonNegativeNumber);
    command.add_option("--max-per-leaf", o.octree.maxPerLeaf, "Split a node holding more triangles than this (the paper's N)")
        ->capture_default_str();
    command.add_option("--max-level", o.octree.maxLevel, "Deepest octree level; the root is level 1")->capture_default_str();
    command.add_option("--strength", o.octree.strength, "Force magnitude at level 1, and per level when it grows linearly")
        ->capture_default_str();
    command
        .add_option_function<std::string>(
            "--growth",
            [&o](const std::string& text) {
                o.octree.growth = text == "doubling" ? MagnitudeGrowth::Doubling : MagnitudeGrowth::Linear;
            },
            "How the magnitude grows with the level: linear (strength x level, the paper's) or doubling (strength x "
            "2^(level - 1)) [default: linear]")
        ->check(CLI::IsMember({"linear", "doubling"}));
    command.add_option("--surface-boost", o.octree.surfaceBoost, "Magnitude factor in leaves holding triangles")
        ->capture_default_str();
    command.add_flag("--flip-normals", o.octree.flipNormals,
                     "Build the field from the triangles' reversed normals (after closed meshes are oriented outward)");
    addSplitRuleOption(command, o.splitRule);
    command.add_option("--tessellate", o.tessellateEdge, "Split mesh edges longer than this first, object units")
        ->check(CLI::PositiveNumber);
    addMaxMemoryOption(command, o.maxMemory);
}

MeshAndField loadMeshAndBuildField(const FieldCliOptions& o, const GlobalOptions& global)
{
    OctreeFieldOptions octree = o.octree;
    if (o.command->count("--margin") > 0) octree.margin = o.margin;
    if (o.splitRule) octree.splitRule = *o.splitRule;

    // A mesh too large for the machine is refused before it is read.
    if (const std::optional<double> limit = o.maxMemory ? o.maxMemory : availableMemory()) {
        try {
            requireMemoryWithin(estimateMeshFileMemory(o.meshPath), *limit, o.maxMemory ? "the limit" : "the memory available",
                                "loading it and building its field");
        } catch (const OptionError& e) {
            throw FileError(o.meshPath, e.what());
        }
    }
    MeshLoadReport report;
    TriangleMesh mesh = loadMesh(o.meshPath, &report);
    for (const std::string& line : report.lines(o.meshPath)) log(global, line);
    if (o.command->count("--tessellate") > 0) mesh = tessellate(mesh, o.tessellateEdge);

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
