#include <vfield/render/embree/path_tracer.h>

#include "paths.h"

namespace vfield {

RenderImage renderReference(const FrameToRender& f)
{
    // Every pixel takes every sample. Sampled adaptively, a pixel whose first
    // path found no sunlit scattering would keep that one dark sample, and
    // the reference would not converge: a displaced cloud lit from behind
    // would come out darker than the fast integrator and Blender Cycles.
    RenderSettings settings = *f.settings;
    settings.image.adaptiveThreshold = 0.0;
    FrameToRender frame = f;
    frame.settings = &settings;
    const Medium medium(frame.volume, settings.medium, frame.motion);
    return renderCameraSamples(frame, [&] {
        return [&, tracer = PathTracer(frame, medium)](const CameraRay& ray, SampleRandom& random, uint32_t) mutable {
            CameraSample seen;
            tracer.setInstant(ray.time, ray.seconds);
            tracer.radiance(ray.origin, ray.dir, PathTracer::Start::Camera, random, &seen);
            return seen;
        };
    });
}

} // namespace vfield
