#include <vfield/render/camera.h>

#include <vfield/core/error.h>

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

} // namespace vfield
