// vfield info FILE.vdb [--checksum]: what an OpenVDB file holds.

#include "command.h"

#include <vfield/core/vdb_file.h>

#include <cstdio>

namespace vfield::cli {

Runner registerInfo(CLI::App& app, const GlobalOptions&)
{
    struct Options {
        std::string path;
        bool checksum = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("info", "List the grids of an OpenVDB file");
    command->add_option("file", o->path, "OpenVDB file")->required();
    command->add_flag("--checksum", o->checksum, "Also print a hash of each grid's contents (independent of the file id)");

    return [o] {
        for (const openvdb::GridBase::Ptr& grid : readVdb(o->path)) {
            const GridSummary s = summarizeGrid(*grid);
            std::printf("%-12s %-8s voxel %-10.6g active %-12llu ", s.name.c_str(), s.type.c_str(), s.voxelSize[0],
                        static_cast<unsigned long long>(s.activeVoxels));
            if (s.activeVoxels == 0) std::printf("bounds empty");
            else
                std::printf("bounds [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g]", s.worldBounds.min()[0], s.worldBounds.min()[1],
                            s.worldBounds.min()[2], s.worldBounds.max()[0], s.worldBounds.max()[1], s.worldBounds.max()[2]);
            std::printf("  %.2f MiB", s.memoryBytes / 1048576.0);
            if (o->checksum) std::printf("  checksum %016llx", static_cast<unsigned long long>(gridChecksum(*grid)));
            std::printf("\n");
        }
    };
}

} // namespace vfield::cli
