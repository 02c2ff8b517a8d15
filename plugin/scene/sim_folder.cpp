#include <vfield/scene/sim_folder.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>
#include <vfield/core/frame_file.h>
#include <vfield/core/hash.h>
#include <vfield/core/vdb_file.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace fs = std::filesystem;

namespace vfield {

namespace {

std::string readFile(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, "cannot open for reading");
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

nlohmann::json vec(const Vec3d& v) { return {v[0], v[1], v[2]}; }
Vec3d vecFromJson(const nlohmann::json& j) { return Vec3d(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()); }

// --- stats.json -------------------------------------------------------------

nlohmann::json toJson(const ClearanceStats& c)
{
    if (c.samples == 0) return nullptr;
    return {
        {"min", c.minimum}, {"p01", c.percentile1}, {"mean", c.mean}, {"penetrations", c.penetrations}, {"samples", c.samples}};
}

ClearanceStats clearanceFromJson(const nlohmann::json& j)
{
    ClearanceStats c;
    if (j.is_null()) return c;
    c.minimum = j.at("min").get<double>();
    c.percentile1 = j.at("p01").get<double>();
    c.mean = j.value("mean", 0.0); // absent from runs saved before it was measured
    c.penetrations = j.at("penetrations").get<uint64_t>();
    c.samples = j.at("samples").get<uint64_t>();
    return c;
}

nlohmann::json toJson(const FrameRecord& r)
{
    const bool any = r.alive > 0;
    nlohmann::json pairs = nlohmann::json::array();
    for (const PairClearance& pair : r.objectPairs)
        pairs.push_back({{"objects", {pair.first, pair.second}}, {"min", pair.minimum}, {"exact", pair.exact}});
    return {{"frame", r.frame},
            {"centroid", any ? vec(r.centroid) : nlohmann::json(nullptr)},
            {"boundsMin", any ? vec(r.bounds.min()) : nlohmann::json(nullptr)},
            {"boundsMax", any ? vec(r.bounds.max()) : nlohmann::json(nullptr)},
            {"alive", r.alive},
            {"removed", r.removed},
            {"substeps", r.substeps},
            {"maxSubsteps", r.maxSubsteps},
            {"dynamicSubsteps", r.dynamicSubsteps},
            {"contacts", r.contacts},
            {"endedInside", r.endedInside},
            {"maxRollChangeDegrees", r.maxRollChange},
            {"seconds", r.seconds},
            {"clearance", {{"particles", toJson(r.particleClearance)}, {"objects", pairs}}}};
}

FrameRecord recordFromJson(const nlohmann::json& j)
{
    FrameRecord r;
    r.frame = j.at("frame").get<int>();
    r.alive = j.at("alive").get<uint64_t>();
    r.removed = j.at("removed").get<uint64_t>();
    r.substeps = j.at("substeps").get<uint64_t>();
    r.maxSubsteps = j.at("maxSubsteps").get<uint32_t>();
    r.dynamicSubsteps = j.at("dynamicSubsteps").get<uint32_t>();
    r.contacts = j.at("contacts").get<uint64_t>();
    r.endedInside = j.value("endedInside", uint64_t(0));
    r.maxRollChange = j.at("maxRollChangeDegrees").get<double>();
    r.seconds = j.value("seconds", 0.0);
    if (!j.at("centroid").is_null()) {
        r.centroid = vecFromJson(j.at("centroid"));
        r.bounds = BBoxd(vecFromJson(j.at("boundsMin")), vecFromJson(j.at("boundsMax")));
    }
    r.particleClearance = clearanceFromJson(j.at("clearance").at("particles"));
    for (const nlohmann::json& pair : j.at("clearance").at("objects"))
        r.objectPairs.push_back({pair.at("objects").at(0).get<std::string>(), pair.at("objects").at(1).get<std::string>(),
                                 pair.at("min").get<double>(), pair.value("exact", true)});
    return r;
}

nlohmann::json recordsToJson(const std::vector<FrameRecord>& records)
{
    nlohmann::json array = nlohmann::json::array();
    for (const FrameRecord& r : records) array.push_back(toJson(r));
    return array;
}

std::vector<FrameRecord> recordsFromJson(const nlohmann::json& array)
{
    std::vector<FrameRecord> records;
    for (const nlohmann::json& r : array) records.push_back(recordFromJson(r));
    return records;
}

// --- tracks.json ------------------------------------------------------------

nlohmann::json objectsToJson(const std::map<std::string, std::vector<TrackEntry>>& objects)
{
    nlohmann::json json = nlohmann::json::object();
    for (const auto& [name, entries] : objects) {
        nlohmann::json& track = json[name];
        for (const TrackEntry& e : entries) {
            const Quatd& q = e.pose.rotation;
            // Transform::matrix() multiplies row vectors (OpenVDB's way); the
            // file states the column-vector form that most hosts take.
            const Mat4d m = e.pose.matrix();
            nlohmann::json matrix = nlohmann::json::array();
            for (int row = 0; row < 4; ++row)
                for (int col = 0; col < 4; ++col) matrix.push_back(m(col, row));
            track.push_back({{"frame", e.frame},
                             {"position", vec(e.pose.translation)},
                             {"orientation", {q.x(), q.y(), q.z(), q.w()}},
                             {"scale", e.pose.scale},
                             {"matrix", matrix},
                             {"velocity", vec(e.velocity)}});
        }
    }
    return json;
}

std::map<std::string, std::vector<TrackEntry>> objectsFromJson(const nlohmann::json& json)
{
    std::map<std::string, std::vector<TrackEntry>> objects;
    for (const auto& [name, entries] : json.items())
        for (const nlohmann::json& e : entries) {
            TrackEntry entry;
            entry.frame = e.at("frame").get<int>();
            const auto q = e.at("orientation").get<std::vector<double>>();
            entry.pose.translation = vecFromJson(e.at("position"));
            entry.pose.rotation = Quatd(q.at(0), q.at(1), q.at(2), q.at(3));
            entry.pose.scale = e.at("scale").get<double>();
            entry.velocity = vecFromJson(e.at("velocity"));
            objects[name].push_back(entry);
        }
    return objects;
}

constexpr const char* kTracksConvention =
    "object-to-world transform of the mesh that export-mesh writes in object space: world = position + "
    "orientation * (scale * p); position: the object's pivot (its mesh's origin) in world space; orientation: "
    "unit quaternion [x, y, z, w] rotating object space (nose +x, up +y) into world space; scale: uniform; "
    "matrix: the same transform as a 4x4 matrix, 16 numbers row by row, for column vectors "
    "(world = M [x, y, z, 1]^T, translation in the last column); velocity: world units per second";

// --- state.bin ----------------------------------------------------------------

constexpr const char* kRunStateHeader = "vfield-run 6";

} // namespace

uint64_t simulationInputsHash(const SimulationSetup& setup, const VolumeOptions& volume)
{
    ContentHash h;
    h.add(std::string(kRunStateHeader));
    hashFields(h, setup, true); // an edited mesh file or elevation model is another simulation
    hashFields(h, volume);
    return h.value();
}

void Tracks::add(const std::string& object, int frame, const DynamicState& state)
{
    mObjects[object].push_back({frame, state.pose, state.velocity});
}

Transform Tracks::pose(const std::string& object, int frame) const
{
    const auto o = mObjects.find(object);
    if (o != mObjects.end())
        for (const TrackEntry& e : o->second)
            if (e.frame == frame) return e.pose;
    throw FileError(mPath, "no pose of \"" + object + "\" at frame " + std::to_string(frame));
}

std::vector<Transform> Tracks::path(const std::string& object, int frame) const
{
    std::vector<TrackEntry> entries;
    if (const auto o = mObjects.find(object); o != mObjects.end())
        std::copy_if(o->second.begin(), o->second.end(), std::back_inserter(entries),
                     [frame](const TrackEntry& e) { return e.frame <= frame; });
    std::sort(entries.begin(), entries.end(), [](const TrackEntry& a, const TrackEntry& b) { return a.frame < b.frame; });
    if (entries.empty() || entries.back().frame != frame)
        throw FileError(mPath, "no pose of \"" + object + "\" at frame " + std::to_string(frame));
    std::vector<Transform> poses;
    for (const TrackEntry& e : entries) poses.push_back(e.pose);
    return poses;
}

std::string Tracks::toJsonText(double fps) const
{
    const nlohmann::json json = {{"fps", fps}, {"convention", kTracksConvention}, {"objects", objectsToJson(mObjects)}};
    return json.dump(1) + "\n";
}

Tracks Tracks::fromJsonText(const std::string& text, const std::string& path)
{
    Tracks tracks;
    tracks.mPath = path;
    try {
        tracks.mObjects = objectsFromJson(nlohmann::json::parse(text).at("objects"));
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable tracks: ") + e.what());
    }
    return tracks;
}

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
    return Tracks::fromJsonText(readFile(path), path);
}

StatsFile SimFolder::readStats() const
{
    const std::string path = statsFile();
    if (!fs::exists(path)) throw FileError(path, "no statistics (simulate the scene first)");
    try {
        const nlohmann::json json = nlohmann::json::parse(readFile(path));
        StatsFile stats;
        stats.fps = json.at("fps").get<double>();
        for (const nlohmann::json& f : json.at("fields"))
            stats.fields.push_back({f.at("object").get<std::string>(), f.at("method").get<std::string>(),
                                    f.at("buildSeconds").get<double>(), f.at("memoryBytes").get<uint64_t>(),
                                    f.at("finestCell").get<double>()});
        stats.frames = recordsFromJson(json.at("frames"));
        return stats;
    } catch (const nlohmann::json::exception& e) {
        throw FileError(path, std::string("unreadable statistics: ") + e.what());
    }
}

bool SimFolder::hasRunState() const { return fs::exists(stateFile()); }

RunState SimFolder::readRunState() const
{
    const std::string path = stateFile();
    std::istringstream in(readFile(path));
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
        state.records = recordsFromJson(nlohmann::json::parse(block()));
        state.tracks.mObjects = objectsFromJson(nlohmann::json::parse(block()));
    } catch (const nlohmann::json::exception&) {
        throw FileError(path, "the run state is corrupt");
    } catch (const std::logic_error&) {
        throw FileError(path, "the run state is corrupt");
    }
    state.tracks.mPath = path;
    return state;
}

void SimFolder::writeFrame(int frame, const DensityGrids& volume, const openvdb::GridBase::Ptr& particles) const
{
    writeVdb(densityFile(frame), {volume.density, volume.velocity});
    writeVdb(particlesFile(frame), {particles});
}

void SimFolder::writeTracks(const Tracks& tracks, double fps) const { writeTextAtomically(tracksFile(), tracks.toJsonText(fps)); }

void SimFolder::writeStats(const std::vector<FrameRecord>& records, const std::vector<FieldRecord>& fields, double fps) const
{
    nlohmann::json fieldsJson = nlohmann::json::array();
    for (const FieldRecord& f : fields)
        fieldsJson.push_back({{"object", f.object},
                              {"method", f.method},
                              {"buildSeconds", f.buildSeconds},
                              {"memoryBytes", f.memoryBytes},
                              {"finestCell", f.finestCell}});
    const nlohmann::json stats = {{"fps", fps}, {"fields", fieldsJson}, {"frames", recordsToJson(records)}};
    writeTextAtomically(statsFile(), stats.dump(1) + "\n");
}

void SimFolder::writeRunState(const RunState& state) const
{
    std::string out = std::string(kRunStateHeader) + "\n";
    for (const std::string& block : {state.scenePath, std::to_string(state.inputsHash), state.simulatorState,
                                     recordsToJson(state.records).dump(), objectsToJson(state.tracks.mObjects).dump()})
        out += std::to_string(block.size()) + "\n" + block;
    writeTextAtomically(stateFile(), out);
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
