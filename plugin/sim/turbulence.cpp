#include <vfield/sim/turbulence.h>

#include <vfield/core/field_visitors.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace vfield {

namespace {

/// x modulo the noise's period (256), in double before rounding to float:
/// far from the origin a float would keep too few bits of the fraction.
float wrapToPeriod(double x) { return float(x - 256.0 * std::floor(x / 256.0)); }

} // namespace

bool TurbulenceSettings::acts(const std::string& target) const
{
    return affects.empty() || std::find(affects.begin(), affects.end(), target) != affects.end();
}

void TurbulenceSettings::validate() const { checkFields(*this); }

Turbulence::Turbulence(const TurbulenceSettings& spec, int firstFrame, double fps)
    : mSpec(spec), mNoise(spec.seed), mFirstFrame(firstFrame), mFps(fps)
{
    // Octaves of independent noise add their mean squares.
    double meanSquare = 0.0, amplitude = 1.0;
    for (int octave = 0; octave < spec.octaves; ++octave, amplitude *= spec.roughness) meanSquare += amplitude * amplitude;
    mOctavesRms = kSwirlRms * std::sqrt(meanSquare);
    mScale = spec.strength / mOctavesRms;
}

Vec3d Turbulence::acceleration(const Vec3d& p, double t) const
{
    // Octave o is grad n(q) x grad n(q + c) = curl(n(q) grad n(q + c)) / f_o,
    // q = p f_o slid down by evolution x t: the curl of a potential, in the
    // noise's own coordinates, so that every octave's swirls are alike but
    // for their size and its amplitude is roughness^o alone. The two reads
    // lie far apart (independent there) and apart per octave (so that lattice
    // zeros do not line up); all of them four at a time. Two noises a swirl
    // instead of the three of the curl of three potentials: a third less work.
    static constexpr float kSecondOffset[3] = {101.7f, 53.3f, 27.9f};
    double scale = mScale, size = mSpec.size;
    if (!mSpec.animation.empty()) {
        const double frame = mFirstFrame + t * mFps;
        scale = valueAtFrame(mSpec.animation, "strength", mSpec.strength, frame) / mOctavesRms;
        size = valueAtFrame(mSpec.animation, "size", size, frame);
    }
    const int samples = 2 * mSpec.octaves;
    std::array<Vec3f, 2 * TurbulenceSettings::kMaxOctaves> points;
    double frequency = 1.0 / size;
    const double slide = mSpec.evolution * t;
    for (int octave = 0; octave < mSpec.octaves; ++octave, frequency *= 2.0) {
        const float shift = 17.31f * float(octave);
        const Vec3f q(wrapToPeriod(p.x() * frequency) + shift, wrapToPeriod(p.y() * frequency + slide) - shift,
                      wrapToPeriod(p.z() * frequency) + 0.5f * shift);
        points[2 * octave] = q;
        points[2 * octave + 1] = q + Vec3f(kSecondOffset[0], kSecondOffset[1], kSecondOffset[2]);
    }
    for (int unused = samples; unused % 4 != 0; ++unused) points[unused] = points[0]; // the last run's idle lanes
    std::array<Vec3f, 2 * TurbulenceSettings::kMaxOctaves> gradients;
    for (int first = 0; first < samples; first += 4) {
        const std::array<NoiseSample, 4> lanes =
            mNoise.sample({points[first], points[first + 1], points[first + 2], points[first + 3]});
        for (int lane = 0; lane < 4; ++lane) gradients[first + lane] = lanes[lane].gradient;
    }
    Vec3d swirl(0.0);
    double amplitude = 1.0;
    for (int octave = 0; octave < mSpec.octaves; ++octave, amplitude *= mSpec.roughness)
        swirl += Vec3d(gradients[2 * octave]).cross(Vec3d(gradients[2 * octave + 1])) * amplitude;
    return swirl * scale;
}

} // namespace vfield
