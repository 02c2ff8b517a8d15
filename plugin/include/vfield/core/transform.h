#pragma once
/// @file transform.h
/// Rigid placement with uniform scale: world = translate + R (scale * object).
/// Rotations are unit quaternions; scene files give Euler angles in degrees,
/// applied about x, then y, then z (all about fixed world axes).

#include <vfield/core/fields.h>
#include <vfield/core/math.h>

#include <openvdb/math/Quat.h>

namespace vfield {

using Quatd = openvdb::math::Quat<double>;

/// q v q^-1 for a unit quaternion (Hamilton convention, right-handed): a
/// positive angle turns counter-clockwise seen from the axis' tip.
inline Vec3d rotate(const Quatd& q, const Vec3d& v)
{
    const Vec3d u(q.x(), q.y(), q.z());
    const Vec3d t = 2.0 * u.cross(v);
    return v + q.w() * t + u.cross(t);
}

struct Transform {
    Vec3d translation{0.0, 0.0, 0.0};
    Quatd rotation = Quatd::identity(); ///< unit quaternion
    double scale = 1.0;

    /// From Euler angles in degrees: about x, then y, then z.
    static Quatd rotationFromDegrees(const Vec3d& degrees);

    Vec3d worldFromObject(const Vec3d& p) const { return translation + rotate(rotation, p * scale); }
    Vec3d objectFromWorld(const Vec3d& p) const { return rotate(rotation.conjugate(), p - translation) / scale; }
    /// Directions rotate but do not scale or move.
    Vec3d rotateToWorld(const Vec3d& v) const { return rotate(rotation, v); }
    Vec3d rotateToObject(const Vec3d& v) const { return rotate(rotation.conjugate(), v); }
    /// The world box around an object-space box, from its eight corners.
    BBoxd worldBounds(const BBoxd& objectBox) const;
    /// The same map as an OpenVDB row-vector matrix (p * M).
    Mat4d matrix() const;
    bool isIdentity() const;
    /// Throws OptionError unless scale is within its range.
    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("translate", self.translation).unit("world units").doc("where the mesh's origin is placed"));
        visit(field("rotateDegrees", self.rotation)
                  .doc("Euler angles about x, then y, then z (fixed world axes)")
                  .defaultText("`[0, 0, 0]`"));
        visit(field("scale", self.scale).range(1e-9, 1e9).doc("uniform scale"));
    }
};

/// Spherical linear interpolation of unit quaternions, the shorter way round.
Quatd slerp(const Quatd& a, Quatd b, double t);

/// The rigid motion between two poses at t in [0, 1]: translation and scale
/// linear, rotation by slerp (a constant angular velocity). t = 1 gives b exactly.
Transform interpolate(const Transform& a, const Transform& b, double t);

} // namespace vfield
