#pragma once
/// @file render_backend.h
/// What every renderer of vfield's frames implements: a frame of a scene
/// (camera, the dynamic objects' poses, the lit cloud) -> image files under
/// an output folder. Embree's (render/embree/embree_backend.h) and POV-Ray's
/// (render/povray/povray_backend.h) implement it; CompositeBackend renders
/// with several at once and puts their images side by side. Which back-ends
/// a run may pick is the run stage's registry (run/render_backends.h):
/// a new back-end is a new class and a line there, and touches no other.
///
/// A back-end prepares what lasts across frames once, before its first frame
/// (a BVH, a mesh include), and names what the scene's settings ask that it
/// cannot draw, so that a run warns once instead of dropping it unseen.

#include <vfield/render/camera.h>
#include <vfield/render/cloud_lighting.h>
#include <vfield/render/cloud_motion.h>
#include <vfield/render/screen_motion.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace vfield {

/// One frame as a back-end draws it (world space).
struct FrameView {
    int frame = 0;
    /// The scene's render settings at the frame's instant, keyed values
    /// resolved (RenderSettings::at); never null.
    const RenderSettings* settings = nullptr;
    Camera camera{Vec3d(0, 0, 1), Vec3d(0.0), Vec3d(0, 1, 0), 45, 1, 1}; ///< at the frame's instant
    std::map<int, Transform> poses;       ///< the dynamic objects' poses at the frame's instant, by object index
    const CloudLighting* cloud = nullptr; ///< the frame's density and the light in it (never null)
    // What a back-end that draws motion blur sees over the shutter
    // (ImageSettings::shutterOpen, shutterClose); the dynamic objects' poses
    // over it are the SurfaceScene's.
    std::optional<Camera> openingCamera;          ///< at the shutter's open; unset: `camera`
    std::optional<Camera> closingCamera;          ///< at its close, when the camera moves over it
    const CloudMotion* motion = nullptr;          ///< the cloud's motion over it; null: none
    const openvdb::Vec3SGrid* velocity = nullptr; ///< the cloud's velocity; null: none
    /// The frames whose light this frame's render gathers (framesAround()),
    /// its own among them; the back-end has seen each, rendered or looked at.
    int lightFrom = 0, lightTo = 0;
    double secondsPerFrame = 1.0 / 24.0; ///< the scene's frames in seconds
    /// The camera and dynamic objects at the frames before and after, for
    /// the passes' motion vectors; null: none.
    const ScreenMotion* screenMotion = nullptr;
    /// Told the fraction of the frame's pixels done, about once a second, one
    /// call at a time (from worker threads); may be unset.
    std::function<void(double fraction)> progress;
};

class RenderBackend {
public:
    virtual ~RenderBackend() = default;

    /// The name a run picks it by ("embree"), and its images' subfolder in a composite.
    virtual std::string name() const = 0;
    /// What the settings ask that this back-end cannot draw, one line each
    /// naming itself and the scene key ("povray cannot draw haze
    /// (sky.hazeDistance): its frames show clear air").
    virtual std::vector<std::string> cannotDraw(const RenderSettings& settings) const = 0;
    /// The files it writes for a frame under the folder out; a frame is
    /// finished when they all exist.
    virtual std::vector<std::string> frameFiles(const std::string& out, int frame) const = 0;

    /// What lasts across frames; called once, before the first frame rendered.
    virtual void prepare() = 0;
    /// Renders the frame into frameFiles(out, frame.frame), each written atomically.
    virtual void render(const FrameView& frame, const std::string& out) = 0;
    /// How many frames either side of a frame its render reads besides its
    /// own (FrameView::lightFrom, lightTo): 0 unless the back-end gathers
    /// light over frames.
    virtual int framesAround() const { return 0; }
    /// Takes from a frame it does not render (yet) what the renders of the
    /// frames around it read, with the frame's surfaces placed: called once
    /// for each such frame, in order, before the renders that read it. The
    /// view's cloud lives until the frame's own render, or the render of a
    /// later frame.
    virtual void look(const FrameView&) {}
    /// Wall-clock seconds spent in render() so far, by back-end name (a
    /// composite reports each of its own).
    virtual std::map<std::string, double> secondsByBackend() const { return {{name(), mSeconds}}; }

protected:
    double mSeconds = 0.0; ///< what render() spent, kept by the implementations
};

/// Several back-ends at once: each renders into OUT/<its name>/, and
/// OUT/frame.####.png holds their PNG frames side by side, in order.
class CompositeBackend : public RenderBackend {
public:
    explicit CompositeBackend(std::vector<std::unique_ptr<RenderBackend>> parts);

    std::string name() const override;
    std::vector<std::string> cannotDraw(const RenderSettings& settings) const override;
    std::vector<std::string> frameFiles(const std::string& out, int frame) const override;
    void prepare() override;
    void render(const FrameView& frame, const std::string& out) override;
    int framesAround() const override;
    void look(const FrameView& frame) override;
    std::map<std::string, double> secondsByBackend() const override;

private:
    std::string partFolder(const std::string& out, const RenderBackend& part) const;
    std::vector<std::unique_ptr<RenderBackend>> mParts;
};

} // namespace vfield
