#include <vfield/render/camera.h>

#include <vfield/core/error.h>

#include <algorithm>
#include <cmath>

namespace vfield {

Camera::Camera(const Vec3d& position, const Vec3d& lookAt, const Vec3d& up, double fovDegrees, int width, int height)
    : mPosition(position), mWidth(width), mHeight(height)
{
    mForward = (lookAt - position).unitSafe();
    mRight = mForward.cross(up).unitSafe();
    if (mRight.length() == 0) throw ValueError("the camera looks along its up vector");
    mUp = mRight.cross(mForward);
    mTanHalf = std::tan(0.5 * fovDegrees * M_PI / 180.0);
    mAspect = double(width) / double(height);
}

Camera Camera::fromSettings(const CameraSettings& s, int width, int height)
{
    return Camera(s.position, s.lookAt, s.up, s.fovDegrees, width, height);
}

Camera Camera::looking(const CameraSettings& s, const Vec3d& position, const Vec3d& target, int width, int height)
{
    return Camera(position, target, s.up, s.fovDegrees, width, height);
}

Vec3d Camera::direction(double x, double y) const
{
    const double u = (2.0 * x / mWidth - 1.0) * mTanHalf * mAspect;
    const double v = (1.0 - 2.0 * y / mHeight) * mTanHalf;
    return (mForward + u * mRight + v * mUp).unitSafe();
}

Camera followCamera(const CameraSettings& settings, const Transform& object, const FirstSurfaceQuery& firstSurface, int width,
                    int height)
{
    Vec3d forward = object.rotateToWorld(Vec3d(1, 0, 0));
    forward[1] = 0.0;
    forward = forward.length() > 1e-9 ? forward.unitSafe() : Vec3d(1, 0, 0);
    const Vec3d up(0, 1, 0), right = forward.cross(up);
    const Vec3d& o = settings.followOffset;
    const Vec3d target = object.translation;
    Vec3d position = target + forward * o[0] + up * o[1] + right * o[2];
    const Vec3d toCamera = position - target;
    const double distance = toCamera.length();
    // Start past the object's own surfaces; stop short of where terrain begins.
    const double start = 0.25 * distance;
    if (distance > 0)
        if (const std::optional<double> hit = firstSurface(target, toCamera / distance, start, distance))
            position = target + toCamera / distance * std::max(start, 0.85 * *hit);
    return Camera::looking(settings, position, target, width, height);
}

} // namespace vfield
