#include <vfield/scene/run_state.h>

#include <vfield/core/error.h>

#include <sstream>

namespace vfield {

namespace {

constexpr const char* kRunStateHeader = "vfield-run 6";

} // namespace

std::string runStateBytes(const RunState& state)
{
    std::string out = std::string(kRunStateHeader) + "\n";
    for (const std::string& block : {state.scenePath, std::to_string(state.inputsHash), state.simulatorState,
                                     frameRecordsJsonText(state.records), state.tracks.objectsJsonText()})
        out += std::to_string(block.size()) + "\n" + block;
    return out;
}

RunState runStateFromBytes(const std::string& bytes, const std::string& path)
{
    std::istringstream in(bytes);
    std::string header;
    std::getline(in, header);
    if (header != kRunStateHeader)
        throw FileError(path, header.rfind("vfield-run ", 0) == 0 ? "a run state of another vfield version (remove the folder)"
                                                                  : "not a vfield run state");
    const auto block = [&]() {
        std::string size;
        std::getline(in, size);
        std::size_t n = 0;
        try {
            n = std::stoull(size);
        } catch (const std::exception&) {
            throw FileError(path, "the run state is corrupt");
        }
        std::string bytes(n, '\0');
        in.read(bytes.data(), std::streamsize(n));
        if (std::size_t(in.gcount()) != n) throw FileError(path, "the run state is truncated");
        return bytes;
    };
    RunState state;
    try {
        state.scenePath = block();
        state.inputsHash = std::stoull(block());
        state.simulatorState = block();
        state.records = frameRecordsFromJsonText(block(), path);
        state.tracks = Tracks::fromObjectsJsonText(block(), path);
    } catch (const std::logic_error&) {
        throw FileError(path, "the run state is corrupt");
    }
    return state;
}

} // namespace vfield
