#pragma once
/// @file camera.h
/// A pinhole camera: right-handed, y up, vertical field of view in degrees.
/// Pixel (0, 0) is the top-left corner of the image. Both back-ends see
/// through the same Camera.

#include <vfield/core/transform.h>
#include <vfield/render/render_settings.h>

#include <functional>
#include <optional>
#include <vector>

namespace vfield {

/// A rectangle of the image in pixels, x in [x0, x1], y in [y0, y1].
struct ImageRegion {
    double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
    double width() const { return x1 - x0; }
    double height() const { return y1 - y0; }
    bool empty() const { return x1 <= x0 || y1 <= y0; }
};

class Camera {
public:
    Camera(const Vec3d& position, const Vec3d& lookAt, const Vec3d& up, double fovDegrees, int width, int height);
    /// The settings' camera, fixed where the settings place it.
    static Camera fromSettings(const CameraSettings& settings, int width, int height);
    /// A camera at position looking at target, with the settings' up and field of view.
    static Camera looking(const CameraSettings& settings, const Vec3d& position, const Vec3d& target, int width, int height);
    /// Between two cameras of one image at t in [0, 1] (a camera moving over
    /// a shutter): its position on the line between theirs, its forward and
    /// up directions their normalised blend, its field of view between theirs.
    static Camera between(const Camera& a, const Camera& b, double t);

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
    /// The image point (pixels, as direction() takes it) where a world point
    /// appears; none for a point not in front of the camera.
    std::optional<Vec2d> imagePoint(const Vec3d& world) const;
    /// The part of the image where something inside `box` can appear: the
    /// bounds of its corners' images, within the image; all of it when the
    /// box reaches behind the camera.
    ImageRegion regionOf(const BBoxd& box) const;

private:
    Vec3d mPosition, mForward, mRight, mUp;
    double mTanHalf, mAspect;
    int mWidth, mHeight;
};

/// The distance to the first surface along origin + t dir (dir unit) for t in
/// [tMin, tMax], or none: how a camera learns what stands in its way.
using FirstSurfaceQuery = std::function<std::optional<double>(const Vec3d& origin, const Vec3d& dir, double tMin, double tMax)>;

/// The camera that follows an object (settings.follow), given the
/// object's path: its poses from the first frame through this one (the last is
/// this frame's). With the follow offset behind the object (x < 0) the camera rides
/// that path, -x units of path length back from the object (the path continued
/// straight behind its first pose where it is shorter), raised by y and moved z
/// to the right of the path's heading there. A camera on the path just flown
/// stays inside the canyon the object flew through and moves as smoothly as the
/// object does (closer in a hairpin, where the path folds), where one fixed in
/// the object's heading frame swings into the walls at every bend. With x >= 0
/// it sits at the offset in the heading frame (x forward, y up, z right). Either way it looks at the object, pulled in front of
/// any surface between the two so that the object stays in view.
Camera followCamera(const CameraSettings& settings, const std::vector<Transform>& path, const FirstSurfaceQuery& firstSurface,
                    int width, int height);

} // namespace vfield
