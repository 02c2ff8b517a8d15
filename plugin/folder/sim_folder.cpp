#include <vfield/folder/sim_folder.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/frame_file.h>
#include <vfield/core/hash.h>
#include <vfield/core/vdb_file.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;

namespace vfield {

SimFolder::SimFolder(std::string path) : mPath(std::move(path)) {}

std::string SimFolder::file(const std::string& name) const { return (fs::path(mPath) / name).string(); }
std::string SimFolder::fieldFile() const { return file("field.vdb"); }
std::string SimFolder::densityFile(int frame) const { return file(frameFileName("density", frame, "vdb")); }
std::string SimFolder::particlesFile(int frame) const { return file(frameFileName("particles", frame, "vdb")); }
std::string SimFolder::tracksFile() const { return file("tracks.json"); }
std::string SimFolder::statsFile() const { return file("stats.json"); }
std::string SimFolder::stateFile() const { return file("state.bin"); }

namespace {

constexpr const char* kInputsHashKey = "vfield:inputsHash";
constexpr const char* kFrameKey = "vfield:frame";

FileFingerprint fingerprint(const std::string& path)
{
    // A megabyte at a time (a whole number of the hash's 8-byte words: the
    // hash of the whole): a frame of millions of particles is hundreds of megabytes.
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, "cannot open for reading");
    std::vector<char> buffer(std::size_t(1) << 20);
    ContentHash hash;
    uint64_t bytes = 0;
    while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0) {
        hash.add(buffer.data(), std::size_t(in.gcount()));
        bytes += uint64_t(in.gcount());
    }
    return {bytes, hash.value()};
}

/// Why a frame file's metadata does not say it was made by this simulation
/// for this frame; empty when it does.
std::string provenanceProblem(const std::string& path, const openvdb::MetaMap& metadata, uint64_t inputsHash, int frame)
{
    const auto hash = metadata.getMetadata<openvdb::StringMetadata>(kInputsHashKey);
    const auto stamped = metadata.getMetadata<openvdb::Int32Metadata>(kFrameKey);
    if (!hash || !stamped)
        return path + " says nothing of the simulation that made it (written by another program or an older vfield)";
    if (hash->value() != hashText(inputsHash))
        return path + " was made by another simulation (inputs hash " + hash->value() + ", the folder's " + hashText(inputsHash) +
               ")";
    if (stamped->value() != frame) return path + " holds frame " + std::to_string(stamped->value());
    return {};
}

/// What every frame file carries: the simulation that made it and its frame.
openvdb::MetaMap frameMetadata(int frame, uint64_t inputsHash)
{
    openvdb::MetaMap metadata;
    metadata.insertMeta(kInputsHashKey, openvdb::StringMetadata(hashText(inputsHash)));
    metadata.insertMeta(kFrameKey, openvdb::Int32Metadata(frame));
    return metadata;
}

} // namespace

DensityGrids SimFolder::readDensityGrids(int frame, std::optional<uint64_t> inputsHash) const
{
    const std::string path = densityFile(frame);
    if (!fs::exists(path)) throw FileError(path, "missing (simulate these frames first)");
    openvdb::MetaMap metadata;
    DensityGrids grids;
    for (const openvdb::GridBase::Ptr& grid : readVdb(path, &metadata)) {
        if (grid->getName() == "vel") grids.velocity = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid);
        if (grid->getName() != "density" || grids.density) continue;
        grids.density = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        if (!grids.density) throw FileError(path, "grid 'density' is a " + grid->valueType() + " grid, not float");
        for (auto it = grids.density->cbeginValueOn(); it; ++it)
            if (!std::isfinite(*it)) {
                const openvdb::Coord c = it.getCoord();
                throw FileError(path, "grid 'density' holds a non-finite value at voxel (" + std::to_string(c.x()) + ", " +
                                          std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")");
            }
    }
    if (!grids.density) throw FileError(path, "no grid named 'density'");
    if (inputsHash) {
        const std::string problem = provenanceProblem(path, metadata, *inputsHash, frame);
        if (!problem.empty()) throw FileError(path, problem.substr(path.size() + 1) + ": simulate the frame again");
    }
    return grids;
}

openvdb::FloatGrid::Ptr SimFolder::readDensity(int frame, std::optional<uint64_t> inputsHash) const
{
    return readDensityGrids(frame, inputsHash).density;
}

Tracks SimFolder::readTracks() const
{
    const std::string path = tracksFile();
    if (!fs::exists(path)) throw FileError(path, "no tracks of the dynamic objects (simulate the scene first)");
    return Tracks::fromJsonText(readFileBytes(path), path);
}

StatsFile SimFolder::readStats() const
{
    const std::string path = statsFile();
    if (!fs::exists(path)) throw FileError(path, "no statistics (simulate the scene first)");
    return statsFromJsonText(readFileBytes(path), path);
}

bool SimFolder::hasRunState() const { return fs::exists(stateFile()); }

RunState SimFolder::readRunState() const { return runStateFromBytes(readFileBytes(stateFile()), stateFile()); }

FileFingerprint SimFolder::writeDensity(int frame, const DensityGrids& grids, uint64_t inputsHash) const
{
    writeVdb(densityFile(frame), {grids.density, grids.velocity}, frameMetadata(frame, inputsHash));
    return fingerprint(densityFile(frame));
}

FileFingerprint SimFolder::writeParticles(int frame, const openvdb::GridBase::Ptr& particles, uint64_t inputsHash) const
{
    writeVdb(particlesFile(frame), {particles}, frameMetadata(frame, inputsHash));
    return fingerprint(particlesFile(frame));
}

openvdb::GridBase::Ptr SimFolder::readParticles(int frame, uint64_t inputsHash) const
{
    const std::string path = particlesFile(frame);
    if (!fs::exists(path)) throw FileError(path, "missing (simulate these frames first)");
    openvdb::MetaMap metadata;
    for (const openvdb::GridBase::Ptr& grid : readVdb(path, &metadata)) {
        if (grid->getName() != "particles") continue;
        const std::string problem = provenanceProblem(path, metadata, inputsHash, frame);
        if (!problem.empty()) throw FileError(path, problem.substr(path.size() + 1) + ": simulate the frame again");
        return grid;
    }
    throw FileError(path, "no grid named 'particles'");
}

FrameCheck SimFolder::checkFrame(const FrameRecord& record, uint64_t inputsHash, bool checkBytes) const
{
    using Status = FrameCheck::Status;
    const int frame = record.frame;
    if (!record.files) return {Status::Missing, "frame " + std::to_string(frame) + " was simulated but not written"};
    const std::pair<std::string, FileFingerprint> files[] = {{densityFile(frame), record.files->density},
                                                             {particlesFile(frame), record.files->particles}};
    for (const auto& [path, written] : files) {
        if (written.bytes == 0) continue; // a shard's frame has no density
        std::error_code ec;
        const uint64_t size = fs::file_size(path, ec);
        if (ec) return {Status::Missing, path + " is missing"};
        openvdb::MetaMap metadata;
        try {
            metadata = readVdbMetadata(path);
        } catch (const FileError& e) {
            return {Status::Corrupt, e.what()};
        }
        const std::string problem = provenanceProblem(path, metadata, inputsHash, frame);
        if (!problem.empty()) return {Status::Foreign, problem};
        if (size != written.bytes)
            return {Status::Corrupt,
                    path + " has " + std::to_string(size) + " bytes, " + std::to_string(written.bytes) + " were written"};
        if (checkBytes && !(fingerprint(path) == written))
            return {Status::Corrupt, path + " is not the file written: its bytes differ"};
    }
    return {};
}

void SimFolder::writeTracks(const Tracks& tracks, double fps) const { writeTextAtomically(tracksFile(), tracks.toJsonText(fps)); }

void SimFolder::writeStats(const StatsFile& stats) const { writeTextAtomically(statsFile(), statsJsonText(stats)); }

void SimFolder::writeRunState(const RunState& state, const std::function<void(std::ostream&)>& writeSimulatorState) const
{
    writeFileAtomically(stateFile(), [&](const std::string& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        vfield::writeRunState(out, state, writeSimulatorState);
        if (!out.flush()) throw FileError(temporary, "cannot write (disk full?)");
    });
}

void SimFolder::clear() const
{
    std::error_code ignored;
    for (const std::string& name : {fieldFile(), tracksFile(), statsFile(), stateFile()}) fs::remove(name, ignored);
    if (!fs::is_directory(mPath)) return;
    for (const auto& entry : fs::directory_iterator(mPath)) {
        const std::string name = entry.path().filename().string();
        const bool isFrame =
            (name.rfind("density.", 0) == 0 || name.rfind("particles.", 0) == 0) && entry.path().extension() == ".vdb";
        if (isFrame) fs::remove(entry.path(), ignored);
    }
}

} // namespace vfield
