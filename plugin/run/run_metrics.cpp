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

/// A frame's density: its centroid and the span along `along` that holds
/// the middle 90% of it (none for an empty grid).
struct DensityPlace {
    Vec3d centroid{0.0};
    double span = 0.0;
    bool empty = true;
};

DensityPlace placeOfDensity(const std::string& path, const Vec3d& along)
{
    DensityPlace place;
    for (const openvdb::GridBase::Ptr& base : readVdb(path)) {
        const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!grid || grid->getName() != "density") continue;
        std::vector<std::pair<double, double>> positionAndMass; // along `along`
        double mass = 0.0;
        Vec3d moment(0.0);
        for (auto it = grid->cbeginValueOn(); it; ++it) {
            if (!it.isVoxelValue() || *it <= 0.0f) continue;
            const Vec3d p = grid->indexToWorld(it.getCoord());
            mass += double(*it);
            moment += p * double(*it);
            positionAndMass.emplace_back(p.dot(along), double(*it));
        }
        if (!(mass > 0.0)) return place;
        std::sort(positionAndMass.begin(), positionAndMass.end());
        double below = 0.0, low = positionAndMass.front().first, high = positionAndMass.back().first;
        bool lowFound = false;
        for (const auto& [position, m] : positionAndMass) {
            below += m;
            if (!lowFound && below >= 0.05 * mass) {
                low = position;
                lowFound = true;
            }
            if (below >= 0.95 * mass) {
                high = position;
                break;
            }
        }
        place.centroid = moment / mass;
        place.span = high - low;
        place.empty = false;
    }
    return place;
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
    // Over the second half: the particles' mean motion and median speeds.
    const int secondHalf = stats.frames[stats.frames.size() / 2].frame;
    Vec3d motion(0.0);
    std::vector<double> medianSpeeds;
    for (const FrameRecord& r : stats.frames) {
        const std::string file = folder.particlesFile(r.frame);
        if (!fs::exists(file)) continue; // frames before the first written
        const ParticleVelocities now = readParticleVelocities(file);
        std::vector<double> speeds;
        for (const Vec3d& v : now.velocity) speeds.push_back(v.length());
        // Slow against the cloud's median, while the cloud itself moves (its
        // median particle at least its own diameter a second): a bank at rest traps nothing.
        const double typical = median(speeds);
        if (r.frame >= secondHalf) {
            medianSpeeds.push_back(typical);
            for (const Vec3d& v : now.velocity) motion += v;
        }
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
    metrics.medianSpeed = median(medianSpeeds);

    // Where the cloud's density stands over the second half.
    std::vector<Vec3d> centroids;
    double spans = 0.0;
    const Vec3d along = motion.length() > 0.0 ? motion.unit() : Vec3d(1, 0, 0);
    for (const FrameRecord& r : stats.frames) {
        if (r.frame < secondHalf || !fs::exists(folder.densityFile(r.frame))) continue;
        const DensityPlace place = placeOfDensity(folder.densityFile(r.frame), along);
        if (place.empty) continue;
        centroids.push_back(place.centroid);
        spans += place.span;
    }
    if (!centroids.empty()) {
        metrics.cloudLength = spans / double(centroids.size());
        for (const Vec3d& c : centroids) metrics.meanCentroid += c / double(centroids.size());
    }
    for (std::size_t a = 0; a < centroids.size(); ++a)
        for (std::size_t b = a + 1; b < centroids.size(); ++b)
            metrics.centroidWander = std::max(metrics.centroidWander, (centroids[a] - centroids[b]).length());
    return metrics;
}

} // namespace vfield
