// The simulator's state after a frame as bytes, to resume from bit-exactly.

#include <vfield/sim/simulator.h>

#include <vfield/core/error.h>

#include <cstring>
#include <sstream>

namespace vfield {

namespace {

template<typename T>
void put(std::ostream& out, const T& value)
{
    out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

template<typename T>
void putVector(std::ostream& out, const std::vector<T>& values)
{
    put(out, uint64_t(values.size()));
    out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(T)));
}

class Reader {
public:
    explicit Reader(const std::string& bytes) : mBytes(bytes) {}
    template<typename T>
    T get()
    {
        T value;
        need(1, sizeof value);
        std::memcpy(&value, mBytes.data() + mAt, sizeof value);
        mAt += sizeof value;
        return value;
    }
    template<typename T>
    void getVector(std::vector<T>& values)
    {
        const auto n = get<uint64_t>();
        need(n, sizeof(T));
        values.resize(n);
        // An empty vector's data() may be null, which memcpy must not be given even for no bytes.
        if (n > 0) std::memcpy(values.data(), mBytes.data() + mAt, n * sizeof(T));
        mAt += n * sizeof(T);
    }
    bool atEnd() const { return mAt == mBytes.size(); }

private:
    /// Throws unless `count` values of `size` bytes remain. Divided, not
    /// multiplied: a damaged count's count * size can wrap to a few bytes.
    void need(uint64_t count, std::size_t size) const
    {
        if (count > (mBytes.size() - mAt) / size) throw ValueError("the saved simulation state is truncated");
    }
    const std::string& mBytes;
    std::size_t mAt = 0;
};

constexpr uint64_t kStateMagic = 0x3574617473646676ull; // "vfdstat5": with origin heights and emitted particles' lives

} // namespace

std::string Simulator::serializeState() const
{
    std::ostringstream out;
    writeState(out);
    return out.str();
}

void Simulator::writeState(std::ostream& out) const
{
    put(out, kStateMagic);
    put(out, int32_t(mFrame));
    put(out, mRemovedTotal);
    put(out, uint64_t(mStates.size()));
    for (const DynamicState& s : mStates) {
        put(out, s.pose.translation);
        put(out, s.pose.rotation);
        put(out, s.pose.scale);
        put(out, s.velocity);
        put(out, s.roll);
        put(out, s.pitch);
    }
    putVector(out, mParticles.position);
    putVector(out, mParticles.velocity);
    putVector(out, mParticles.rest);
    putVector(out, mParticles.rest2);
    putVector(out, mParticles.peak);
    putVector(out, mParticles.origin);
    putVector(out, mParticles.birth);
    putVector(out, mParticles.death);
    putVector(out, mParticles.fade);
    putVector(out, mParticles.id);
    putVector(out, mParticles.radius);
    putVector(out, mParticles.cloud);
}

void Simulator::restoreState(const std::string& bytes)
{
    Reader in(bytes);
    if (in.get<uint64_t>() != kStateMagic) throw ValueError("not a vfield simulation state");
    const int frame = in.get<int32_t>();
    const auto removed = in.get<uint64_t>();
    if (in.get<uint64_t>() != mStates.size()) throw ValueError("the saved state is of another scene (object count)");
    std::vector<DynamicState> states(mStates.size());
    for (DynamicState& s : states) {
        s.pose.translation = in.get<Vec3d>();
        s.pose.rotation = in.get<Quatd>();
        s.pose.scale = in.get<double>();
        s.velocity = in.get<Vec3d>();
        s.roll = in.get<double>();
        s.pitch = in.get<double>();
    }
    ParticleSet particles;
    in.getVector(particles.position);
    in.getVector(particles.velocity);
    in.getVector(particles.rest);
    in.getVector(particles.rest2);
    in.getVector(particles.peak);
    in.getVector(particles.origin);
    in.getVector(particles.birth);
    in.getVector(particles.death);
    in.getVector(particles.fade);
    in.getVector(particles.id);
    in.getVector(particles.radius);
    in.getVector(particles.cloud);
    const std::size_t n = particles.size();
    // Every particle has a life when a cloud emits, none otherwise.
    const auto lives = [&](const std::vector<float>& values) { return values.size() == (mEmitters.empty() ? 0 : n); };
    if (!in.atEnd() || particles.velocity.size() != n || particles.rest.size() != n ||
        particles.rest2.size() != (mSetup.solver.restPeriod == 0 ? 0 : n) || particles.peak.size() != n ||
        particles.origin.size() != n || particles.id.size() != n || particles.radius.size() != n || particles.cloud.size() != n ||
        !lives(particles.birth) || !lives(particles.death) || !lives(particles.fade))
        throw ValueError("the saved simulation state is inconsistent");
    for (const uint16_t c : particles.cloud)
        if (c >= mSetup.clouds.size()) throw ValueError("the saved state is of another scene (cloud index)");
    if (frame < mSetup.firstFrame || frame > mSetup.lastFrame) throw ValueError("the saved state's frame is out of range");
    mFrame = frame;
    mRemovedTotal = removed;
    mStates = std::move(states);
    mStatesAtFrameStart = mStates;
    mParticles = std::move(particles);
    mKeptBounds = {};
    // The emitters' births are a function of time alone: counted again up to the frame.
    for (Emitter& emitter : mEmitters) {
        emitter.restart();
        emitter.birthsUpTo(mSetup.frameTime(mFrame));
    }
    updateRestPositions();
}

} // namespace vfield
