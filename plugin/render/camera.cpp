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

Camera Camera::between(const Camera& a, const Camera& b, double t)
{
    if (t == 0.0) return a;
    if (t == 1.0) return b;
    Camera c = a;
    c.mPosition = a.mPosition + (b.mPosition - a.mPosition) * t;
    c.mForward = (a.mForward + (b.mForward - a.mForward) * t).unitSafe();
    c.mRight = c.mForward.cross(a.mUp + (b.mUp - a.mUp) * t).unitSafe();
    c.mUp = c.mRight.cross(c.mForward);
    c.mTanHalf = a.mTanHalf + (b.mTanHalf - a.mTanHalf) * t;
    return c;
}

Vec3d Camera::direction(double x, double y) const
{
    const double u = (2.0 * x / mWidth - 1.0) * mTanHalf * mAspect;
    const double v = (1.0 - 2.0 * y / mHeight) * mTanHalf;
    return (mForward + u * mRight + v * mUp).unitSafe();
}

std::optional<Vec2d> Camera::imagePoint(const Vec3d& world) const
{
    const Vec3d d = world - mPosition;
    const double depth = d.dot(mForward);
    if (depth <= 0.0) return std::nullopt;
    // direction()'s mapping inverted.
    return Vec2d((d.dot(mRight) / (depth * mTanHalf * mAspect) + 1.0) * 0.5 * mWidth,
                 (1.0 - d.dot(mUp) / (depth * mTanHalf)) * 0.5 * mHeight);
}

ImageRegion Camera::regionOf(const BBoxd& box) const
{
    const ImageRegion image{0.0, 0.0, double(mWidth), double(mHeight)};
    ImageRegion region{image.x1, image.y1, image.x0, image.y0};
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3d p((corner & 1 ? box.max() : box.min())[0], (corner & 2 ? box.max() : box.min())[1],
                      (corner & 4 ? box.max() : box.min())[2]);
        const std::optional<Vec2d> point = imagePoint(p);
        if (!point) return image;
        const double x = (*point)[0], y = (*point)[1];
        region = {std::min(region.x0, x), std::min(region.y0, y), std::max(region.x1, x), std::max(region.y1, y)};
    }
    return {std::max(region.x0, image.x0), std::max(region.y0, image.y0), std::min(region.x1, image.x1),
            std::min(region.y1, image.y1)};
}

namespace {

/// The unit horizontal direction of v, or fallback where v is vertical.
Vec3d horizontal(Vec3d v, const Vec3d& fallback)
{
    v[1] = 0.0;
    return v.length() > 1e-9 ? v.unitSafe() : fallback;
}

} // namespace

Camera followCamera(const CameraSettings& settings, const std::vector<Transform>& path, const FirstSurfaceQuery& firstSurface,
                    int width, int height)
{
    if (path.empty() || !settings.follow) throw ValueError("a following camera needs an object to follow and its pose");
    const Transform& object = path.back();
    const Vec3d& o = settings.follow->offset;
    const Vec3d target = object.translation, up(0, 1, 0);
    Vec3d forward = horizontal(object.rotateToWorld(Vec3d(1, 0, 0)), Vec3d(1, 0, 0));
    Vec3d anchor = target + forward * o[0];
    if (o[0] < 0) {
        // Walk back along the path until -o[0] units of it are behind.
        double remaining = -o[0];
        std::size_t i = path.size() - 1;
        for (; i > 0; --i) {
            const Vec3d step = path[i].translation - path[i - 1].translation;
            const double length = step.length();
            if (length > 0 && length >= remaining) {
                anchor = path[i].translation - step * (remaining / length);
                forward = horizontal(step, forward);
                break;
            }
            remaining -= length;
        }
        if (i == 0) {
            forward = horizontal(path.front().rotateToWorld(Vec3d(1, 0, 0)), forward);
            anchor = path.front().translation - forward * remaining;
        }
    }
    Vec3d position = anchor + up * o[1] + forward.cross(up) * o[2];
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
