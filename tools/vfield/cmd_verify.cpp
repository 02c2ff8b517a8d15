// vfield verify DIR: whether every frame a simulation folder records is still
// there as it was written: present, stamped by the folder's simulation, of the
// size and bytes stats.json records.

#include "command.h"

#include <vfield/folder/sim_folder.h>

#include <tbb/parallel_for.h>

#include <cstdio>
#include <map>

namespace vfield::cli {

Runner registerVerify(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        std::string folder;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "verify", "Report a simulation folder's frames that are missing, foreign (made by another simulation) or corrupt");
    command->add_option("folder", o->folder, "Simulation folder (vfield simulate's output)")->required();

    return [o, &global] {
        const SimFolder folder(o->folder);
        const StatsFile stats = folder.readStats();
        std::vector<FrameCheck> checks(stats.frames.size());
        tbb::parallel_for(std::size_t(0), stats.frames.size(),
                          [&](std::size_t i) { checks[i] = folder.checkFrame(stats.frames[i], stats.inputsHash); });
        std::map<FrameCheck::Status, int> counts;
        for (std::size_t i = 0; i < checks.size(); ++i) {
            ++counts[checks[i].status];
            if (checks[i].status != FrameCheck::Status::Good)
                std::printf("frame %d: %s: %s\n", stats.frames[i].frame, enumName(checks[i].status), checks[i].detail.c_str());
        }
        const int bad = int(checks.size()) - counts[FrameCheck::Status::Good];
        log(global, o->folder + ": " + std::to_string(checks.size()) + " frames recorded, " +
                        std::to_string(counts[FrameCheck::Status::Good]) + " good, " +
                        std::to_string(counts[FrameCheck::Status::Missing]) + " missing, " +
                        std::to_string(counts[FrameCheck::Status::Foreign]) + " foreign, " +
                        std::to_string(counts[FrameCheck::Status::Corrupt]) + " corrupt");
        if (bad > 0) throw CommandExit{1, ""};
    };
}

} // namespace vfield::cli
