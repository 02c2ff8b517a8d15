#pragma once
/// @file camera_samples.h
/// The pixel loop every integrator of vfield's renderer shares: tiles in
/// parallel, samplesPerPixel camera rays a pixel (one through the centre, or
/// all jittered over the pixel), each with its own counter-based random
/// stream, averaged into premultiplied RGBA and the nearest surface's depth.

#include <vfield/core/stopwatch.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/embree/sample_random.h>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <limits>
#include <mutex>

namespace vfield {

/// What one camera ray sees.
struct CameraSample {
    Vec3d radiance{0.0};
    double alpha = 0.0;                                   ///< coverage: 1 unless it sees a transparent sky
    float depth = std::numeric_limits<float>::infinity(); ///< to the first surface
};

/// Pixels done, counted across worker threads, and told as a fraction of the
/// frame at most once a second, one call at a time.
class PixelProgress {
public:
    PixelProgress(const std::function<void(double fraction)>& report, std::size_t pixels)
        : mReport(report), mPixels(double(pixels))
    {}
    void add(std::size_t pixels)
    {
        const std::size_t done = mDone += pixels;
        if (!mReport) return;
        const std::unique_lock<std::mutex> lock(mMutex, std::try_to_lock);
        if (!lock.owns_lock() || !mSinceTold.lapAfter(1.0)) return;
        mReport(double(done) / mPixels);
    }

private:
    const std::function<void(double)>& mReport;
    double mPixels;
    std::atomic<std::size_t> mDone{0};
    std::mutex mMutex;
    Stopwatch mSinceTold; ///< guarded by mMutex
};

/// makeSampler() is called once per tile (so that it can hold per-thread
/// state such as grid accessors) and returns a callable
/// CameraSample(const Vec3d& dir, SampleRandom& random, uint32_t pixel) for
/// unit camera directions; a pixel's samples come one after another.
template<typename MakeSampler>
RenderImage renderCameraSamples(const FrameToRender& f, const MakeSampler& makeSampler)
{
    const ImageSettings& settings = f.settings->image;
    const int width = settings.width, height = settings.height, samplesPerPixel = settings.samplesPerPixel;
    RenderImage image;
    image.width = width;
    image.height = height;
    image.rgba.assign(std::size_t(width) * height * 4, 0.0f);
    image.depth.assign(std::size_t(width) * height, std::numeric_limits<float>::infinity());

    PixelProgress progress(f.progress, std::size_t(width) * height);
    const int tile = 16;
    tbb::parallel_for(tbb::blocked_range2d<int>(0, height, tile, 0, width, tile), [&](const tbb::blocked_range2d<int>& r) {
        auto sampler = makeSampler();
        for (int y = r.rows().begin(); y != r.rows().end(); ++y)
            for (int x = r.cols().begin(); x != r.cols().end(); ++x) {
                const uint32_t pixel = uint32_t(y) * uint32_t(width) + uint32_t(x);
                Vec3d colour(0.0);
                double alpha = 0.0;
                float depth = std::numeric_limits<float>::infinity();
                for (int sample = 0; sample < samplesPerPixel; ++sample) {
                    SampleRandom random(uint32_t(f.frame), pixel, uint32_t(sample));
                    // One sample at the pixel centre, the rest jittered over it.
                    const double jx = samplesPerPixel == 1 ? 0.5 : random.next();
                    const double jy = samplesPerPixel == 1 ? 0.5 : random.next();
                    const CameraSample seen = sampler(f.camera.direction(x + jx, y + jy), random, pixel);
                    colour += seen.radiance;
                    alpha += seen.alpha;
                    depth = std::min(depth, seen.depth);
                }
                const double n = samplesPerPixel;
                float* out = &image.rgba[4 * std::size_t(pixel)];
                out[0] = float(colour[0] / n);
                out[1] = float(colour[1] / n);
                out[2] = float(colour[2] / n);
                out[3] = float(alpha / n);
                image.depth[pixel] = depth;
            }
        progress.add(r.rows().size() * r.cols().size());
    });
    return image;
}

} // namespace vfield
