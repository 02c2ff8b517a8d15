#pragma once
/// @file camera_path.h
/// A path through points travelled at constant speed, as a camera on a
/// motion path moves in Houdini or on Blender's Follow Path: a centripetal
/// Catmull-Rom spline (Yuksel, Schaefer and Keyser, "Parameterization and
/// applications of Catmull-Rom curves", 2011: through every point, without
/// cusps or loops within a segment), measured by its arc length.

#include <vfield/core/math.h>

#include <vector>

namespace vfield {

class CameraPath {
public:
    /// Through points, in order (at least two, no two in a row equal).
    explicit CameraPath(std::vector<Vec3d> points);

    /// The path's length, world units.
    double length() const { return mArcLength.back(); }
    /// The point `distance` along the path (clamped to its ends).
    Vec3d point(double distance) const;
    /// The unit direction of travel there.
    Vec3d direction(double distance) const;

private:
    /// Samples per segment of the arc-length table: the speed it gives is
    /// constant to well within 0.1% on paths whose turns are not sharp.
    static constexpr int kSamplesPerSegment = 256;

    /// Segment s (between points s and s + 1) at its parameter t in [0, 1].
    Vec3d segmentPoint(std::size_t segment, double t) const;

    std::vector<Vec3d> mPoints;     ///< with a mirrored point before the first and after the last
    std::vector<double> mArcLength; ///< at each sample, kSamplesPerSegment a segment, from 0
};

} // namespace vfield
