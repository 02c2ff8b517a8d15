#include <vfield/sim/emission.h>

#include <vfield/core/error.h>
#include <vfield/core/vdb_file.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace vfield {

namespace {

/// Uniform double in [0, 1) from a 64-bit generator (the standard's
/// distributions differ between libraries; this does not).
template<typename Random>
double unitRandom(Random& random)
{
    return double(random() >> 11) * (1.0 / 9007199254740992.0);
}

/// A particle's own random stream (Steele, Lea and Flood's SplitMix64): cheap
/// to start, so every emitted particle has one, drawn from its number alone.
struct ParticleRandom {
    using result_type = uint64_t;
    uint64_t state;
    static constexpr uint64_t min() { return 0; }
    static constexpr uint64_t max() { return ~uint64_t(0); }
    uint64_t operator()()
    {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
};

/// A point of the cloud's shape, uniform: rejection sampling from the box
/// around it. With billow the shape's surface is pulled in by up to that
/// fraction of its radii where the billow noise is high, so the cloud is
/// lumps with creases between (every point within 1 - billow of the centre is
/// kept, so the loop ends).
template<typename Random>
Vec3d samplePointIn(const CloudSettings& cloud, const GradientNoise& noise, Random& random)
{
    const double billowSize =
        cloud.billowSize > 0.0 ? cloud.billowSize : std::min({cloud.radii[0], cloud.radii[1], cloud.radii[2]}) / 3.0;
    for (;;) {
        const Vec3d u(2 * unitRandom(random) - 1, 2 * unitRandom(random) - 1, 2 * unitRandom(random) - 1);
        const Vec3d offset(u[0] * cloud.radii[0], u[1] * cloud.radii[1], u[2] * cloud.radii[2]);
        // The shape's norm: 1 on its surface.
        const double r =
            cloud.shape == CloudSettings::Shape::Box ? std::max({std::abs(u[0]), std::abs(u[1]), std::abs(u[2])}) : u.length();
        if (r > 1.0) continue;
        if (cloud.billow > 0.0 && r > 1.0 - cloud.billow * double(billow(noise, Vec3f(offset / billowSize), {3, 2.0, 0.5})))
            continue;
        return cloud.center + offset;
    }
}

/// The index of the entry whose share of the cumulative total holds u in [0, 1).
std::size_t pickByWeight(const std::vector<double>& cumulative, double u)
{
    const double target = u * cumulative.back();
    return std::min(std::size_t(std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin()),
                    cumulative.size() - 1);
}

/// The generalized winding number of a closed mesh around p: 1 inside, 0
/// outside (Jacobson, Kavan and Sorkine-Hornung 2013; each triangle's solid
/// angle by Van Oosterom and Strackee's formula).
double windingNumber(const TriangleMesh& mesh, const Vec3d& p)
{
    double sum = 0.0;
    for (const Vec3ui& t : mesh.triangles) {
        const Vec3d a = Vec3d(mesh.points[t[0]]) - p, b = Vec3d(mesh.points[t[1]]) - p, c = Vec3d(mesh.points[t[2]]) - p;
        const double la = a.length(), lb = b.length(), lc = c.length();
        const double numerator = a.dot(b.cross(c));
        const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * std::atan2(numerator, denominator);
    }
    return sum / (4.0 * M_PI);
}

/// The streams a particle draws from, apart: its lifetime's and its place's.
constexpr uint64_t kLifetimeStream = 1, kPlaceStream = 2;

} // namespace

ParticleSet emitClouds(const SimulationSettings& setup)
{
    int64_t total = 0;
    for (const CloudSettings& c : setup.clouds)
        if (!c.emission) total += c.count;
    ParticleSet particles;
    particles.reserve(std::size_t(total));
    uint32_t nextId = 0;
    for (std::size_t c = 0; c < setup.clouds.size(); ++c) {
        const CloudSettings& cloud = setup.clouds[c];
        if (cloud.emission) continue;
        std::mt19937_64 random(setup.seed * 0x9e3779b97f4a7c15ull ^ (cloud.seed + 0x632be59bd9b4e019ull * (c + 1)));
        const GradientNoise puffs(cloud.seed);
        for (int64_t k = 0; k < cloud.count; ++k) {
            particles.position.emplace_back(samplePointIn(cloud, puffs, random));
            particles.velocity.emplace_back(cloud.velocity);
            particles.rest.push_back(particles.position.back());
            particles.peak.push_back(particles.position.back().y());
            particles.origin.push_back(particles.position.back().y());
            particles.id.push_back(nextId++);
            particles.radius.push_back(float(cloud.particleRadius));
            particles.cloud.push_back(uint16_t(c));
        }
    }
    return particles;
}

double lifeFade(const CloudEmissionSettings& emission, double birth, double death, double t)
{
    if (emission.fade <= 0.0) return 1.0;
    const auto ramp = [&](double seconds) {
        const double x = std::clamp(seconds / emission.fade, 0.0, 1.0);
        return x * x * (3.0 - 2.0 * x);
    };
    return ramp(t - birth) * (std::isinf(death) ? 1.0 : ramp(death - t));
}

Emitter::Emitter(const SimulationSettings& setup, std::size_t cloud, uint32_t firstId, const TriangleMesh* mesh)
    : mSetup(setup), mCloud(setup.clouds[cloud]), mEmission(*mCloud.emission), mIndex(cloud), mFirstId(firstId), mMesh(mesh),
      mPuffs(mCloud.seed)
{
    switch (mEmission.from) {
    case EmissionSource::Shape:
        break;
    case EmissionSource::Surface:
        for (std::size_t t = 0; t < mesh->triangleCount(); ++t)
            mCumulative.push_back((mCumulative.empty() ? 0.0 : mCumulative.back()) + 0.5 * mesh->areaVector(t).length());
        if (mCumulative.empty() || !(mCumulative.back() > 0.0))
            throw ValueError("cloud \"" + mCloud.name + "\" emits from the surface of \"" + mEmission.object +
                             "\", which has none");
        break;
    case EmissionSource::Inside:
        mMeshBounds = mesh->bounds();
        break;
    case EmissionSource::Volume: {
        openvdb::FloatGrid::Ptr grid;
        for (const openvdb::GridBase::Ptr& candidate : readVdb(mEmission.file))
            if (candidate->getName() == mEmission.grid) grid = openvdb::gridPtrCast<openvdb::FloatGrid>(candidate);
        if (!grid) throw FileError(mEmission.file, "no float grid named \"" + mEmission.grid + "\"");
        mVolumeTransform = grid->transformPtr();
        for (auto it = grid->cbeginValueOn(); it; ++it) {
            if (!(double(*it) > mEmission.threshold)) continue;
            const openvdb::CoordBBox box = it.getBoundingBox();
            mBoxes.emplace_back(Vec3d(box.min().asVec3d()) - Vec3d(0.5), Vec3d(box.max().asVec3d()) + Vec3d(0.5));
            mCumulative.push_back((mCumulative.empty() ? 0.0 : mCumulative.back()) + double(*it) * double(box.volume()));
        }
        if (mCumulative.empty())
            throw FileError(mEmission.file, "grid \"" + mEmission.grid + "\" has no voxel above the threshold " +
                                                numberText(mEmission.threshold));
        break;
    }
    }
}

uint64_t Emitter::streamSeed(int64_t k, uint64_t purpose) const
{
    ParticleRandom mix{(mSetup.seed * 0x9e3779b97f4a7c15ull ^ (mCloud.seed + 0x632be59bd9b4e019ull * (mIndex + 1))) + purpose};
    mix.state += uint64_t(k) * 0xd6e8feb86659fd93ull;
    return mix();
}

double Emitter::integralUpTo(double frame) const
{
    const double to = std::min(frame, mEmission.end);
    if (!(to > mEmission.start)) return 0.0;
    const KeyTrack* keyed = mEmission.animation.find("rate");
    const double frames = keyed ? keyed->integrate(mEmission.start, to) : mEmission.rate * (to - mEmission.start);
    return frames / mSetup.fps;
}

int64_t Emitter::dueBy(double t) const { return int64_t(std::floor(integralUpTo(mSetup.frameAt(t)) + 0.5)); }

uint32_t Emitter::idCount() const
{
    return uint32_t(std::min<int64_t>(dueBy(mSetup.frameTime(mSetup.lastFrame)), std::numeric_limits<uint32_t>::max()));
}

double Emitter::frameOfIntegral(double target) const
{
    // The integral only grows: halve the bracket from the emitter's whole
    // span to the last bit, so that the frame found is the same however the
    // births were asked for (frame by frame, or all at once on a resume).
    double low = mEmission.start, high = std::max(low, std::min(mEmission.end, double(mSetup.lastFrame)));
    for (;;) {
        const double middle = 0.5 * (low + high);
        if (middle <= low || middle >= high) return high;
        (integralUpTo(middle) < target ? low : high) = middle;
    }
}

std::vector<Emitter::Birth> Emitter::birthsUpTo(double t)
{
    std::vector<Birth> births;
    for (const int64_t due = dueBy(t); mNext < due; ++mNext) {
        const double time = (frameOfIntegral(double(mNext) + 0.5) - mSetup.firstFrame) / mSetup.fps;
        ParticleRandom random{streamSeed(mNext, kLifetimeStream)};
        double lifetime = std::numeric_limits<double>::infinity();
        if (mEmission.lifetime > 0.0) lifetime = mEmission.lifetime + mEmission.lifetimeSpread * (2.0 * unitRandom(random) - 1.0);
        while (!mDeaths.empty() && mDeaths.top() <= time) mDeaths.pop();
        if (int64_t(mDeaths.size()) >= mCloud.count) continue;
        mDeaths.push(time + lifetime);
        births.push_back({mNext, mFirstId + uint32_t(mNext), time, time + lifetime});
    }
    return births;
}

void Emitter::restart()
{
    mNext = 0;
    mDeaths = {};
}

Vec3d Emitter::position(int64_t k) const
{
    ParticleRandom random{streamSeed(k, kPlaceStream)};
    switch (mEmission.from) {
    case EmissionSource::Shape:
        return samplePointIn(mCloud, mPuffs, random);
    case EmissionSource::Surface: {
        const Vec3ui& t = mMesh->triangles[pickByWeight(mCumulative, unitRandom(random))];
        double u = unitRandom(random), v = unitRandom(random);
        if (u + v > 1.0) { // the other half of the parallelogram, folded back
            u = 1.0 - u;
            v = 1.0 - v;
        }
        const Vec3d a(mMesh->points[t[0]]), b(mMesh->points[t[1]]), c(mMesh->points[t[2]]);
        return a + (b - a) * u + (c - a) * v;
    }
    case EmissionSource::Inside:
        for (;;) {
            const Vec3d u(unitRandom(random), unitRandom(random), unitRandom(random));
            const Vec3d p = mMeshBounds.min() + Vec3d(u[0] * mMeshBounds.extents()[0], u[1] * mMeshBounds.extents()[1],
                                                      u[2] * mMeshBounds.extents()[2]);
            if (windingNumber(*mMesh, p) > 0.5) return p;
        }
    case EmissionSource::Volume: {
        const BBoxd& box = mBoxes[pickByWeight(mCumulative, unitRandom(random))];
        const Vec3d u(unitRandom(random), unitRandom(random), unitRandom(random));
        const Vec3d index = box.min() + Vec3d(u[0] * box.extents()[0], u[1] * box.extents()[1], u[2] * box.extents()[2]);
        return mVolumeTransform->indexToWorld(index);
    }
    }
    return mCloud.center;
}

} // namespace vfield
