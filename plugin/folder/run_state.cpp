#include <vfield/folder/run_state.h>

#include <vfield/core/error.h>

#include <cstdio>
#include <ostream>
#include <sstream>

namespace vfield {

namespace {

constexpr const char* kRunStateHeader = "vfield-run 6";

} // namespace

void writeRunState(std::ostream& out, const RunState& state, const std::function<void(std::ostream&)>& writeSimulatorState)
{
    // Each block is its size in bytes on a line, then the bytes.
    const auto block = [&out](const std::string& bytes) { out << bytes.size() << "\n" << bytes; };
    out << kRunStateHeader << "\n";
    block(state.scenePath);
    block(std::to_string(state.inputsHash));
    if (writeSimulatorState) {
        // Streamed: its size is known once written, into a line kept wide enough for any.
        const std::streampos sizeLine = out.tellp();
        out << std::string(20, '0') << "\n";
        const std::streampos start = out.tellp();
        writeSimulatorState(out);
        const std::streampos end = out.tellp();
        char size[32];
        std::snprintf(size, sizeof size, "%020lld", static_cast<long long>(end - start));
        out.seekp(sizeLine);
        out.write(size, 20);
        out.seekp(end);
    } else {
        block(state.simulatorState);
    }
    block(frameRecordsJsonText(state.records));
    block(state.tracks.objectsJsonText());
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
