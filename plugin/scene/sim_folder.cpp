#include <vfield/scene/sim_folder.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/frame_file.h>
#include <vfield/core/vdb_file.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

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

openvdb::FloatGrid::Ptr SimFolder::readDensity(int frame) const
{
    const std::string path = densityFile(frame);
    if (!fs::exists(path)) throw FileError(path, "missing (simulate these frames first)");
    for (const openvdb::GridBase::Ptr& grid : readVdb(path)) {
        if (grid->getName() != "density") continue;
        openvdb::FloatGrid::Ptr density = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        if (!density) throw FileError(path, "grid 'density' is a " + grid->valueType() + " grid, not float");
        for (auto it = density->cbeginValueOn(); it; ++it)
            if (!std::isfinite(*it)) {
                const openvdb::Coord c = it.getCoord();
                throw FileError(path, "grid 'density' holds a non-finite value at voxel (" + std::to_string(c.x()) + ", " +
                                          std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")");
            }
        return density;
    }
    throw FileError(path, "no grid named 'density'");
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

void SimFolder::writeFrame(int frame, const DensityGrids& volume, const openvdb::GridBase::Ptr& particles) const
{
    writeVdb(densityFile(frame), {volume.density, volume.velocity});
    writeVdb(particlesFile(frame), {particles});
}

void SimFolder::writeTracks(const Tracks& tracks, double fps) const { writeTextAtomically(tracksFile(), tracks.toJsonText(fps)); }

void SimFolder::writeStats(const std::vector<FrameRecord>& records, const std::vector<FieldRecord>& fields, double fps) const
{
    writeTextAtomically(statsFile(), statsJsonText({fps, fields, records}));
}

void SimFolder::writeRunState(const RunState& state) const { writeTextAtomically(stateFile(), runStateBytes(state)); }

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
