#include <vfield/render/camera_path.h>

#include <vfield/core/error.h>

#include <algorithm>
#include <cmath>

namespace vfield {

CameraPath::CameraPath(std::vector<Vec3d> points)
{
    if (points.size() < 2) throw ValueError("a camera path needs at least two points");
    for (std::size_t i = 1; i < points.size(); ++i)
        if (points[i] == points[i - 1])
            throw ValueError("a camera path's points " + std::to_string(i - 1) + " and " + std::to_string(i) + " are the same");
    // The ends continue straight: mirrored neighbours give the first and
    // last segments their tangents.
    mPoints.push_back(2.0 * points[0] - points[1]);
    mPoints.insert(mPoints.end(), points.begin(), points.end());
    mPoints.push_back(2.0 * points.back() - points[points.size() - 2]);

    const std::size_t segments = points.size() - 1;
    mArcLength.reserve(segments * kSamplesPerSegment + 1);
    mArcLength.push_back(0.0);
    Vec3d previous = segmentPoint(0, 0.0);
    for (std::size_t s = 0; s < segments; ++s)
        for (int k = 1; k <= kSamplesPerSegment; ++k) {
            const Vec3d p = segmentPoint(s, double(k) / kSamplesPerSegment);
            mArcLength.push_back(mArcLength.back() + (p - previous).length());
            previous = p;
        }
}

Vec3d CameraPath::segmentPoint(std::size_t segment, double t) const
{
    // Barry and Goldman's pyramid over the four points around the segment,
    // knots spaced by the square root of the distances (centripetal).
    const Vec3d* p = &mPoints[segment];
    double knot[4] = {0.0, 0.0, 0.0, 0.0};
    for (int i = 1; i < 4; ++i) knot[i] = knot[i - 1] + std::sqrt((p[i] - p[i - 1]).length());
    const double u = knot[1] + t * (knot[2] - knot[1]);
    const auto blend = [&](const Vec3d& a, const Vec3d& b, double ka, double kb) {
        return kb == ka ? a : a * ((kb - u) / (kb - ka)) + b * ((u - ka) / (kb - ka));
    };
    const Vec3d a1 = blend(p[0], p[1], knot[0], knot[1]);
    const Vec3d a2 = blend(p[1], p[2], knot[1], knot[2]);
    const Vec3d a3 = blend(p[2], p[3], knot[2], knot[3]);
    const Vec3d b1 = blend(a1, a2, knot[0], knot[2]);
    const Vec3d b2 = blend(a2, a3, knot[1], knot[3]);
    return blend(b1, b2, knot[1], knot[2]);
}

Vec3d CameraPath::point(double distance) const
{
    const double d = std::clamp(distance, 0.0, length());
    // The last sample at or before d, and the parameter between it and the next.
    const std::size_t k = std::min(std::size_t(std::upper_bound(mArcLength.begin(), mArcLength.end(), d) - mArcLength.begin()),
                                   mArcLength.size() - 1) -
                          1;
    const double span = mArcLength[k + 1] - mArcLength[k];
    const double within = span > 0.0 ? (d - mArcLength[k]) / span : 0.0;
    const std::size_t segment = std::min(k / kSamplesPerSegment, mPoints.size() - 4);
    const double t = (double(k - segment * kSamplesPerSegment) + within) / kSamplesPerSegment;
    return segmentPoint(segment, t);
}

Vec3d CameraPath::direction(double distance) const
{
    const double step = 1e-4 * length();
    const double ahead = std::min(distance + step, length()), behind = std::max(distance - step, 0.0);
    return (point(ahead) - point(behind)).unitSafe();
}

} // namespace vfield
