#include <vfield/render/screen_motion.h>

#include <utility>

namespace vfield {

namespace {

Vec3d worldPoint(const ScreenMotion::Instant& instant, int object, const Vec3d& point)
{
    const auto pose = instant.poses.find(object);
    return pose == instant.poses.end() ? point : pose->second.worldFromObject(point);
}

/// Where the sky along dir appears: a point far enough away that the
/// camera's own travel does not move it.
std::optional<Vec2d> skyPoint(const Camera& camera, const Vec3d& dir)
{
    constexpr double kFar = 1e9;
    return camera.imagePoint(camera.position() + dir * kFar);
}

/// From a to b in pixels, y up; none when either is unseen.
Vec2d motion(const std::optional<Vec2d>& a, const std::optional<Vec2d>& b)
{
    if (!a || !b) return Vec2d(0.0);
    return Vec2d((*b)[0] - (*a)[0], (*a)[1] - (*b)[1]);
}

/// The motion from the previous frame to this one, then on to the next.
Vec4d between(const std::optional<Vec2d>& previous, const std::optional<Vec2d>& current, const std::optional<Vec2d>& next)
{
    const Vec2d fromPrevious = motion(previous, current), toNext = motion(current, next);
    return Vec4d(fromPrevious[0], fromPrevious[1], toNext[0], toNext[1]);
}

} // namespace

ScreenMotion::ScreenMotion(Instant previous, Instant current, Instant next)
    : mPrevious(std::move(previous)), mCurrent(std::move(current)), mNext(std::move(next))
{}

Vec4d ScreenMotion::ofPoint(int object, const Vec3d& point) const
{
    return between(mPrevious.camera.imagePoint(worldPoint(mPrevious, object, point)),
                   mCurrent.camera.imagePoint(worldPoint(mCurrent, object, point)),
                   mNext.camera.imagePoint(worldPoint(mNext, object, point)));
}

Vec4d ScreenMotion::ofSky(const Vec3d& dir) const
{
    return between(skyPoint(mPrevious.camera, dir), skyPoint(mCurrent.camera, dir), skyPoint(mNext.camera, dir));
}

} // namespace vfield
