#pragma once
/// @file camera.h
/// A pinhole camera: right-handed, y up, vertical field of view in degrees.
/// Pixel (0, 0) is the top-left corner of the image. Both back-ends see
/// through the same Camera.

#include <vfield/core/transform.h>
#include <vfield/render/render_settings.h>

#include <functional>
#include <optional>

namespace vfield {

class Camera {
public:
    Camera(const Vec3d& position, const Vec3d& lookAt, const Vec3d& up, double fovDegrees, int width, int height);
    /// The settings' camera, fixed where the settings place it.
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

/// The distance to the first surface along origin + t dir (dir unit) for t in
/// [tMin, tMax], or none: how a camera learns what stands in its way.
using FirstSurfaceQuery = std::function<std::optional<double>(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax)>;

/// The camera that follows an object (settings.followObject): behind and above
/// it by settings.followOffset in its heading frame (x forward, y up, z right),
/// looking at it, and pulled in front of any surface between the two so that
/// the object stays in view.
Camera followCamera(const CameraSettings& settings, const Transform& object, const FirstSurfaceQuery& firstSurface, int width,
                    int height);

} // namespace vfield
