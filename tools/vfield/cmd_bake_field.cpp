// vfield bake-field MESH -o field.vdb: the octree field as OpenVDB grids.

#include "field_cli_options.h"

#include <vfield/core/vdb_file.h>
#include <vfield/field/field_grid.h>

#include <cstdio>

namespace vfield::cli {

Runner registerBakeField(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        FieldCliOptions field;
        std::string output;
        double voxelSize = 0.0;
        bool forceOnly = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("bake-field", "Voxelize a mesh's octree field into an OpenVDB file");
    addFieldOptions(*command, o->field);
    command->add_option("-o,--output", o->output, "Output .vdb file")->required();
    command->add_option("--voxel-size", o->voxelSize, "Voxel edge, object units [default: the finest leaf's side]")
        ->check(CLI::PositiveNumber);
    command->add_flag("--force-only", o->forceOnly, "Write only the `force` grid, not `level` and `surface`");

    return [o, command, &global] {
        const MeshAndField built = loadMeshAndBuildField(o->field, global);
        VoxelizeOptions voxelize;
        if (command->count("--voxel-size") > 0) voxelize.voxelSize = o->voxelSize;
        voxelize.withLevel = voxelize.withSurface = !o->forceOnly;
        const FieldGrids grids = voxelizeField(built.field, voxelize);
        writeVdb(o->output, grids.all());
        char line[256];
        std::snprintf(line, sizeof line, "%s: force grid, voxel %.6g, %llu active voxels, %.1f MiB in memory", o->output.c_str(),
                      grids.force->voxelSize()[0], static_cast<unsigned long long>(grids.force->activeVoxelCount()),
                      grids.force->memUsage() / 1048576.0);
        log(global, line);
    };
}

} // namespace vfield::cli
