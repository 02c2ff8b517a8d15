// vfield bake-field MESH -o field.vdb: the octree field as OpenVDB grids, or
// with --format fga as the vector-field file that Unreal Engine imports.

#include "field_cli_options.h"

#include <vfield/core/vdb_file.h>
#include <vfield/field/fga_file.h>
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
        std::string format = "vdb";
        int cells = 0;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command =
        app.add_subcommand("bake-field", "Voxelize a mesh's octree field into an OpenVDB file, or an FGA vector field");
    addFieldOptions(*command, o->field);
    command->add_option("-o,--output", o->output, "Output file: .vdb, or .fga with --format fga")->required();
    command->add_option("--voxel-size", o->voxelSize, "Voxel edge, object units [default: the finest leaf's side]")
        ->check(CLI::PositiveNumber);
    command->add_flag("--force-only", o->forceOnly, "Write only the `force` grid, not `level` and `surface`");
    command
        ->add_option("--format", o->format,
                     "vdb (OpenVDB grids) or fga (Unreal Engine's vector field: the force at cell centres)")
        ->check(CLI::IsMember({"vdb", "fga"}))
        ->capture_default_str();
    command->add_option("--cells", o->cells, "fga: cells per axis over the root cube [default: the finest leaves', at most 128]")
        ->check(CLI::Range(1, 1024));

    return [o, command, &global] {
        const MeshAndField built = loadMeshAndBuildField(o->field, global);
        if (o->format == "fga") {
            const int cells = o->cells > 0 ? o->cells : std::min(1 << (built.field.depth() - 1), 128);
            writeFga(o->output, sampleField(built.field, cells));
            log(global, o->output + ": " + std::to_string(cells) + "^3 vectors over the root cube (FGA)");
            return;
        }
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
