#pragma once
/// @file shard_merge.h
/// The last step of a sharded simulation (shard_part.h). Per frame, the K
/// shards' particles are put together (in id order, then in spatial order,
/// whichever machine moved them), splatted and written into OUT as one run
/// writes a frame, stamped with the simulation's inputs hash, so that
/// renderers and hosts read OUT as any simulation folder. stats.json holds
/// the parts' records summed (a frame's seconds and stages: every part's
/// plus the merge's); tracks.json and field.vdb are the objects' part's.
///
/// The density grids are those one run of the whole cloud writes, bit for
/// bit: the splat's sums do not depend on the particles' order
/// (density_splat.h).
/// A merge resumes after the last frame it merged that is still as written.
/// OUT holds a merge or a single run, never both: each refuses the other's.

#include <vfield/run/simulation_run.h>

#include <string>

namespace vfield {

/// Merges the frames options.firstFrame..lastFrame of the count shards of
/// the simulation in outputDir (options' frames, progress, preparing and
/// folder waiting apply; its part and memory limit do not). Throws FileError
/// naming a part that lacks a frame, or whose files are not as written, with
/// the command that makes it.
SimulateSummary mergeShards(const Scene& scene, const std::string& outputDir, int count, const SimulateOptions& options = {});

} // namespace vfield
