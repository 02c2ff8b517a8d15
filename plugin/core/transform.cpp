#include <vfield/core/transform.h>

#include <vfield/core/field_visitors.h>

#include <cmath>

namespace vfield {

Quatd Transform::rotationFromDegrees(const Vec3d& degrees)
{
    const double toRadians = M_PI / 180.0;
    const Quatd x(Vec3d(1, 0, 0), degrees[0] * toRadians);
    const Quatd y(Vec3d(0, 1, 0), degrees[1] * toRadians);
    const Quatd z(Vec3d(0, 0, 1), degrees[2] * toRadians);
    return (z * y * x).unit(); // x first
}

Mat4d Transform::matrix() const
{
    // Rows are the images of the object axes (OpenVDB multiplies row vectors).
    Mat4d m = Mat4d::identity();
    for (int row = 0; row < 3; ++row) {
        Vec3d axis(0.0);
        axis[row] = 1.0;
        const Vec3d image = rotate(rotation, axis) * scale;
        for (int col = 0; col < 3; ++col) m(row, col) = image[col];
    }
    m.setTranslation(translation);
    return m;
}

BBoxd Transform::worldBounds(const BBoxd& objectBox) const
{
    BBoxd box;
    for (int corner = 0; corner < 8; ++corner) box.expand(worldFromObject(boxCorner(objectBox, corner)));
    return box;
}

bool Transform::isIdentity() const { return translation == Vec3d(0.0) && scale == 1.0 && rotation.eq(Quatd::identity()); }

void Transform::validate() const { checkFields(*this); }

Quatd slerp(const Quatd& a, Quatd b, double t)
{
    double dot = a.x() * b.x() + a.y() * b.y() + a.z() * b.z() + a.w() * b.w();
    if (dot < 0) {
        b = Quatd(-b.x(), -b.y(), -b.z(), -b.w());
        dot = -dot;
    }
    if (dot > 0.9995) { // nearly equal: normalized lerp
        const Quatd q(a.x() + t * (b.x() - a.x()), a.y() + t * (b.y() - a.y()), a.z() + t * (b.z() - a.z()),
                      a.w() + t * (b.w() - a.w()));
        return q.unit();
    }
    const double theta = std::acos(dot), s = std::sin(theta);
    const double wa = std::sin((1 - t) * theta) / s, wb = std::sin(t * theta) / s;
    return Quatd(wa * a.x() + wb * b.x(), wa * a.y() + wb * b.y(), wa * a.z() + wb * b.z(), wa * a.w() + wb * b.w());
}

Transform interpolate(const Transform& a, const Transform& b, double t)
{
    if (t == 1.0) return b;
    Transform pose;
    pose.translation = a.translation + (b.translation - a.translation) * t;
    pose.rotation = slerp(a.rotation, b.rotation, t);
    pose.scale = a.scale + (b.scale - a.scale) * t;
    return pose;
}

} // namespace vfield
