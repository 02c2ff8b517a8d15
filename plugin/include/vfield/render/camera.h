#pragma once
/// @file camera.h
/// A pinhole camera: right-handed, y up, vertical field of view in degrees.
/// Pixel (0, 0) is the top-left corner of the image.

#include <vfield/render/render_settings.h>

namespace vfield {

class Camera {
public:
    Camera(const Vec3d& position, const Vec3d& lookAt, const Vec3d& up, double fovDegrees, int width, int height);
    /// The settings' camera (a following camera is placed by followPosition).
    static Camera fromSettings(const CameraSettings& settings, int width, int height);
    /// A camera at position looking at target, with the settings' up and field of view.
    static Camera looking(const CameraSettings& settings, const Vec3d& position, const Vec3d& target, int width, int height);

    const Vec3d& position() const { return mPosition; }
    /// The camera's frame, unit vectors: forward, right and up (right = forward x up).
    const Vec3d& forward() const { return mForward; }
    const Vec3d& right() const { return mRight; }
    const Vec3d& up() const { return mUp; }
    /// tan(vertical field of view / 2) and width / height: the image plane at
    /// distance 1 spans +-tanHalfFov() * aspect() across and +-tanHalfFov() up.
    double tanHalfFov() const { return mTanHalf; }
    double aspect() const { return mAspect; }
    /// Unit direction through the image point (x right, y down, in pixels).
    Vec3d direction(double x, double y) const;

private:
    Vec3d mPosition, mForward, mRight, mUp;
    double mTanHalf, mAspect;
    int mWidth, mHeight;
};

} // namespace vfield
