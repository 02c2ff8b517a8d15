#pragma once
/// @file screen_motion.h
/// Motion vectors, as Blender's Vector pass holds them and its Vector Blur
/// node and Nuke's VectorBlur read them: how far, in pixels, what a pixel
/// sees moves on the screen from the previous frame to this one (X, Y) and
/// from this one to the next (Z, W), x to the right and y up. A surface's
/// point moves with its object and the camera; the sky with the camera's
/// turning alone. The cloud is not in them, as volumes are not in Cycles'.

#include <vfield/render/camera.h>

#include <map>

namespace vfield {

class ScreenMotion {
public:
    /// Where the camera and the dynamic objects stand at one frame.
    struct Instant {
        Camera camera;
        std::map<int, Transform> poses; ///< the dynamic objects', by object index
    };

    ScreenMotion(Instant previous, Instant current, Instant next);

    /// Of a point of `object`: in the object's own space when the object is
    /// dynamic (one of the poses), else in world space. A point behind a
    /// camera moves nowhere towards or from that frame.
    Vec4d ofPoint(int object, const Vec3d& point) const;
    /// Of the sky seen along the world direction `dir`.
    Vec4d ofSky(const Vec3d& dir) const;

private:
    Instant mPrevious, mCurrent, mNext;
};

} // namespace vfield
