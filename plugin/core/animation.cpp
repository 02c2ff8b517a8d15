#include <vfield/core/animation.h>

#include <algorithm>
#include <cmath>

namespace vfield {

namespace {

double signOf(double x) { return x > 0.0 ? 1.0 : x < 0.0 ? -1.0 : 0.0; }

void normalise(double* v, int components)
{
    double length = 0.0;
    for (int c = 0; c < components; ++c) length += v[c] * v[c];
    length = std::sqrt(length);
    if (length > 0.0)
        for (int c = 0; c < components; ++c) v[c] /= length;
}

} // namespace

KeyTrack::KeyTrack(std::vector<double> frames, std::vector<double> values, int components, Interpolation interpolation,
                   bool isDirection)
    : mFrames(std::move(frames)), mValues(std::move(values)), mComponents(components), mInterpolation(interpolation),
      mIsDirection(isDirection)
{
    if (mIsDirection)
        for (std::size_t i = 0; i < mFrames.size(); ++i) normalise(&mValues[i * std::size_t(mComponents)], mComponents);
    if (mInterpolation == Interpolation::Smooth) computeSlopes();
}

void KeyTrack::computeSlopes()
{
    // Steffen (1990), eq. 11 inside: the harmonic-like blend of the two
    // secants, limited to twice the smaller one and zero where they differ in
    // sign; the ends flat (eases in and out, and keeps the first and last
    // keys' values as the extremes of their intervals).
    const std::size_t n = mFrames.size();
    mSlopes.assign(n * std::size_t(mComponents), 0.0);
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const double hBefore = mFrames[i] - mFrames[i - 1], hAfter = mFrames[i + 1] - mFrames[i];
        for (int c = 0; c < mComponents; ++c) {
            const double before = (value(i)[c] - value(i - 1)[c]) / hBefore;
            const double after = (value(i + 1)[c] - value(i)[c]) / hAfter;
            const double blend = (before * hAfter + after * hBefore) / (hBefore + hAfter);
            mSlopes[i * std::size_t(mComponents) + std::size_t(c)] =
                (signOf(before) + signOf(after)) * std::min({std::abs(before), std::abs(after), 0.5 * std::abs(blend)});
        }
    }
}

void KeyTrack::evaluate(double frame, double* out) const
{
    const std::size_t n = mFrames.size();
    const auto copyKey = [&](std::size_t i) { std::copy(value(i), value(i) + mComponents, out); };
    if (frame <= mFrames.front()) return copyKey(0);
    if (frame >= mFrames.back()) return copyKey(n - 1);
    // The key at or before frame; frames lies strictly between the first and last.
    const std::size_t i = std::size_t(std::upper_bound(mFrames.begin(), mFrames.end(), frame) - mFrames.begin()) - 1;
    if (mInterpolation == Interpolation::Step) return copyKey(i);
    const double h = mFrames[i + 1] - mFrames[i], t = (frame - mFrames[i]) / h;
    const double* a = value(i);
    const double* b = value(i + 1);
    if (mInterpolation == Interpolation::Linear) {
        for (int c = 0; c < mComponents; ++c) out[c] = a[c] + (b[c] - a[c]) * t;
    } else {
        // Cubic Hermite between the two keys with their slopes (per frame).
        const double t2 = t * t, t3 = t2 * t;
        const double h00 = 2.0 * t3 - 3.0 * t2 + 1.0, h10 = t3 - 2.0 * t2 + t, h01 = -2.0 * t3 + 3.0 * t2, h11 = t3 - t2;
        const double* slopeA = &mSlopes[i * std::size_t(mComponents)];
        const double* slopeB = &mSlopes[(i + 1) * std::size_t(mComponents)];
        for (int c = 0; c < mComponents; ++c) out[c] = h00 * a[c] + h10 * h * slopeA[c] + h01 * b[c] + h11 * h * slopeB[c];
    }
    if (mIsDirection) normalise(out, mComponents);
}

double KeyTrack::integrate(double from, double to) const
{
    const auto valueAt = [this](double frame) {
        double v[6];
        evaluate(frame, v);
        return v[0];
    };
    // Piece by piece between keys: constant outside them and under step
    // keys, linear or cubic between them, where Simpson's rule is exact.
    double sum = 0.0, a = from;
    for (std::size_t i = 0; a < to; ++i) {
        while (i < mFrames.size() && mFrames[i] <= a) ++i;
        const double b = i < mFrames.size() ? std::min(mFrames[i], to) : to;
        if (mInterpolation == Interpolation::Step || a < mFrames.front() || a >= mFrames.back()) sum += valueAt(a) * (b - a);
        else sum += (b - a) / 6.0 * (valueAt(a) + 4.0 * valueAt(0.5 * (a + b)) + valueAt(b));
        a = b;
    }
    return sum;
}

const KeyTrack* Animation::find(const std::string& key) const
{
    for (const auto& [name, track] : mTracks)
        if (name == key) return &track;
    return nullptr;
}

void Animation::set(const std::string& key, KeyTrack track)
{
    erase(key);
    mTracks.emplace_back(key, std::move(track));
}

void Animation::erase(const std::string& key)
{
    mTracks.erase(std::remove_if(mTracks.begin(), mTracks.end(), [&](const auto& entry) { return entry.first == key; }),
                  mTracks.end());
}

} // namespace vfield
