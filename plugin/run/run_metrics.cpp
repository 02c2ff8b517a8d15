#include <vfield/run/run_metrics.h>

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>

#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace fs = std::filesystem;

namespace vfield {

namespace {

double median(std::vector<double> values)
{
    if (values.empty()) return 0.0;
    const auto middle = values.begin() + std::ptrdiff_t(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

ObjectMotion measureTrack(const std::string& name, const std::vector<TrackEntry>& track, double fps)
{
    ObjectMotion motion;
    motion.name = name;
    std::vector<double> speeds;
    for (const TrackEntry& e : track) speeds.push_back(e.velocity.length());
    motion.cruiseSpeed = median(speeds);

    // Jerk from the frames' velocities: two differences, each over a frame.
    std::vector<Vec3d> acceleration;
    for (std::size_t f = 1; f < track.size(); ++f) acceleration.push_back((track[f].velocity - track[f - 1].velocity) * fps);
    std::size_t jerks = 0;
    for (std::size_t f = 1; f < acceleration.size(); ++f) {
        const double jerk = ((acceleration[f] - acceleration[f - 1]) * fps).length();
        motion.meanJerk += jerk;
        motion.peakJerk = std::max(motion.peakJerk, jerk);
        ++jerks;
    }
    if (jerks > 0) motion.meanJerk /= double(jerks);

    // Stalls: spells below 10% of the cruise speed that last over a second.
    int spell = 0;
    for (std::size_t f = 0; f <= speeds.size(); ++f) {
        if (f < speeds.size() && speeds[f] < 0.1 * motion.cruiseSpeed) {
            ++spell;
            continue;
        }
        if (spell > fps) motion.stallSeconds += spell / fps;
        spell = 0;
    }
    return motion;
}

/// One frame's particles: id, velocity and radius.
struct ParticleVelocities {
    std::vector<int32_t> id;
    std::vector<Vec3d> velocity;
    std::vector<double> radius;
};

ParticleVelocities readParticleVelocities(const std::string& path)
{
    ParticleVelocities out;
    for (const openvdb::GridBase::Ptr& base : readVdb(path)) {
        const auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(base);
        if (!grid) continue;
        for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
            const auto& descriptor = leaf->attributeSet().descriptor();
            for (const char* name : {"v", "id", "pscale"})
                if (descriptor.find(name) == openvdb::points::AttributeSet::INVALID_POS)
                    throw FileError(path, std::string("the particles have no \"") + name + "\" attribute");
            const openvdb::points::AttributeHandle<openvdb::Vec3f> velocity(leaf->constAttributeArray("v"));
            const openvdb::points::AttributeHandle<int32_t> id(leaf->constAttributeArray("id"));
            const openvdb::points::AttributeHandle<float> radius(leaf->constAttributeArray("pscale"));
            for (auto index = leaf->beginIndexOn(); index; ++index) {
                out.id.push_back(id.get(*index));
                out.velocity.emplace_back(velocity.get(*index));
                out.radius.push_back(radius.get(*index));
            }
        }
    }
    return out;
}

} // namespace

RunMetrics measureRun(const std::string& path)
{
    const SimFolder folder(path);
    const StatsFile stats = folder.readStats();
    if (stats.frames.empty()) throw FileError(folder.statsFile(), "records no frame");
    RunMetrics metrics;
    metrics.folder = path;
    metrics.fields = stats.fields;
    metrics.frames = int(stats.frames.size());
    metrics.particles = stats.frames.front().alive;

    uint64_t clearanceSamples = 0, substeps = 0, stepped = 0;
    std::map<std::string, PairClearance> closest; // per dynamic object
    for (std::size_t f = 0; f < stats.frames.size(); ++f) {
        const FrameRecord& r = stats.frames[f];
        const ClearanceStats& c = r.particleClearance;
        if (c.samples > 0) {
            metrics.minClearance = clearanceSamples == 0 ? c.minimum : std::min(metrics.minClearance, c.minimum);
            metrics.meanClearance += c.mean * double(c.samples);
            clearanceSamples += c.samples;
            metrics.penetrations += c.penetrations;
        }
        metrics.contacts += r.contacts;
        metrics.simulateSeconds += r.seconds;
        if (f > 0) { // the first frame records the initial state
            substeps += r.substeps;
            stepped += r.alive;
        }
        for (const PairClearance& pair : r.objectPairs)
            for (const std::string& name : {pair.first, pair.second}) {
                const auto it = closest.find(name);
                if (it == closest.end() || pair.minimum < it->second.minimum) closest[name] = pair;
            }
    }
    if (clearanceSamples > 0) metrics.meanClearance /= double(clearanceSamples);
    if (stepped > 0) metrics.substepsPerParticleFrame = double(substeps) / double(stepped);

    const Tracks tracks = fs::exists(folder.tracksFile()) ? folder.readTracks() : Tracks();
    for (const auto& [name, track] : tracks.objects()) {
        ObjectMotion motion = measureTrack(name, track, stats.fps);
        if (const auto it = closest.find(name); it != closest.end()) {
            motion.minClearance = it->second.minimum;
            motion.clearanceExact = it->second.exact;
        }
        metrics.objects.push_back(motion);
    }

    // Particles by id from frame to frame: how their paths turn, and who stops.
    std::vector<Vec3d> previous;
    std::vector<int> previousFrame, slowFrames;
    std::vector<uint8_t> trapped;
    double turning = 0.0, length = 0.0;
    for (const FrameRecord& r : stats.frames) {
        const std::string file = folder.particlesFile(r.frame);
        if (!fs::exists(file)) continue; // frames before the first written
        const ParticleVelocities now = readParticleVelocities(file);
        std::vector<double> speeds;
        for (const Vec3d& v : now.velocity) speeds.push_back(v.length());
        // Slow against the cloud's median, while the cloud itself moves (its
        // median particle at least its own diameter a second): a bank at rest traps nothing.
        const double typical = median(speeds);
        const bool moving = typical >= 2.0 * median(now.radius);
        const double slow = 0.1 * typical;
        for (std::size_t p = 0; p < now.id.size(); ++p) {
            const auto id = std::size_t(now.id[p]);
            if (id >= previous.size()) {
                previous.resize(id + 1);
                previousFrame.resize(id + 1, -2);
                slowFrames.resize(id + 1, 0);
                trapped.resize(id + 1, 0);
            }
            const Vec3d& v = now.velocity[p];
            if (previousFrame[id] == r.frame - 1) {
                const Vec3d& u = previous[id];
                turning += std::atan2(u.cross(v).length(), u.dot(v));
                length += 0.5 * (u.length() + v.length()) / stats.fps;
            }
            slowFrames[id] = moving && speeds[p] < slow ? slowFrames[id] + 1 : 0;
            if (slowFrames[id] > stats.fps) trapped[id] = 1;
            previous[id] = v;
            previousFrame[id] = r.frame;
        }
    }
    if (length > 0.0) metrics.meanCurvature = turning / length;
    metrics.trapped = uint64_t(std::count(trapped.begin(), trapped.end(), uint8_t(1)));
    return metrics;
}

} // namespace vfield
