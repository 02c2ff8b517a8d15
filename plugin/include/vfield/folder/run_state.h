#pragma once
/// @file run_state.h
/// state.bin: what a resumed run needs, written last after every frame (it
/// marks the frame complete): the simulator's state after that frame, the
/// records and tracks so far, and what made them: the scene file and the
/// hash of the simulation's inputs (inputs_hash.h).

#include <vfield/folder/stats_file.h>
#include <vfield/folder/tracks.h>

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace vfield {

struct RunState {
    std::string scenePath; ///< absolute
    uint64_t inputsHash = 0;
    std::string simulatorState; ///< Simulator::serializeState(); empty in a merged folder (shard_merge.h)
    std::vector<FrameRecord> records;
    Tracks tracks;
};

/// Writes state.bin's bytes to out. The simulator's state comes from
/// writeSimulatorState when given (Simulator::writeState, streamed into the
/// file), else from state.simulatorState.
void writeRunState(std::ostream& out, const RunState& state, const std::function<void(std::ostream&)>& writeSimulatorState = {});
/// Reads state.bin's bytes (path names it in errors). Throws FileError for
/// another version's state or a corrupt or truncated one.
RunState runStateFromBytes(const std::string& bytes, const std::string& path);

} // namespace vfield
