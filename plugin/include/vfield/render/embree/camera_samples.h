#pragma once
/// @file camera_samples.h
/// The pixel loop every integrator of vfield's renderer shares: bands of rows
/// in parallel, samplesPerPixel camera rays a pixel (one through the centre,
/// or all jittered over the pixel), each with its own counter-based random
/// stream, shared among the pixels around it by the pixel filter into
/// premultiplied RGBA, and the nearest surface's depth.
/// With the shutter open, a pixel's samples are spread over it, one in each
/// of samplesPerPixel equal parts (stratified), from a camera placed at
/// each sample's time.

#include <vfield/core/stopwatch.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/embree/sample_random.h>
#include <vfield/render/embree/surfaces.h>
#include <vfield/render/pixel_filter.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <functional>
#include <limits>
#include <mutex>
#include <tuple>
#include <vector>

namespace vfield {

/// What one camera ray sees, split as the passes split it: the cloud's own
/// light in front of what lies behind the cloud (the first surface, or the
/// sky), which shows through the cloud's transmittance.
struct CameraSample {
    Vec3d cloud{0.0};                                     ///< the light the cloud sends along the ray
    double transmittance = 1.0;                           ///< of the cloud, up to what lies behind it
    Vec3d behind{0.0};                                    ///< the first surface's light or a drawn sky's; 0 for a transparent sky
    double behindAlpha = 0.0;                             ///< its coverage: 1 unless a transparent sky
    float depth = std::numeric_limits<float>::infinity(); ///< to the first surface
    // The first surface's, for the passes:
    int object = -1;           ///< its object; -1: none seen
    Vec3d objectPosition{0.0}; ///< the point seen, SurfaceHit::objectPosition
    Vec3d normal{0.0};         ///< its shading normal
    double shadow = 0.0;       ///< the share of the sun's light on it that the cloud takes

    Vec3d radiance() const { return cloud + behind * transmittance; }
    double alpha() const { return 1.0 - (1.0 - behindAlpha) * transmittance; }
};

/// One pixel's sums for the passes (RenderPasses) of the samples that reach
/// it, each weighted by the pixel filter, in the order they come.
class PassSums {
public:
    /// A sample, the screen motion of what it sees (ScreenMotion's), its
    /// weight here, and whether it is the pixel's own: the object seen
    /// nearest is an own sample's, never a neighbour's.
    void add(const CameraSample& seen, const Vec4d& screenMotion, double weight, bool own)
    {
        mWeight += weight;
        mCloud += seen.cloud * weight;
        mCloudAlpha += (1.0 - seen.transmittance) * weight;
        mBehindSeen += seen.behind * (seen.transmittance * weight);
        mBehindAlphaSeen += seen.behindAlpha * seen.transmittance * weight;
        mTransmittance += seen.transmittance * weight;
        mBehind += seen.behind * weight;
        mBehindAlpha += seen.behindAlpha * weight;
        mShadow += seen.shadow * weight;
        mNormal += seen.normal * weight;
        mVector += screenMotion * weight;
        if (own && seen.object >= 0 && seen.depth < mNearest) {
            mNearest = seen.depth;
            mObject = seen.object;
        }
    }

    /// Adds the sums of samples taken elsewhere.
    void add(const PassSums& other)
    {
        mWeight += other.mWeight;
        mCloud += other.mCloud;
        mCloudAlpha += other.mCloudAlpha;
        mBehindSeen += other.mBehindSeen;
        mBehindAlphaSeen += other.mBehindAlphaSeen;
        mTransmittance += other.mTransmittance;
        mBehind += other.mBehind;
        mBehindAlpha += other.mBehindAlpha;
        mShadow += other.mShadow;
        mNormal += other.mNormal;
        mVector += other.mVector;
    }

    /// Writes the pixel's values at index `pixel` of each pass.
    void write(RenderPasses& passes, std::size_t pixel) const
    {
        const double n = mWeight;
        const auto put = [](std::vector<float>& pass, std::size_t at, const Vec3d& v) {
            for (int c = 0; c < 3; ++c) pass[at + c] = float(v[c]);
        };
        put(passes.cloud, 4 * pixel, mCloud / n);
        passes.cloud[4 * pixel + 3] = float(mCloudAlpha / n);
        // Weighted by the transmittance, the cloud over the surfaces is the
        // beauty; where nothing shows through, the samples' plain mean.
        const bool showsThrough = mTransmittance > 1e-9 * n;
        put(passes.surfaces, 4 * pixel, showsThrough ? mBehindSeen / mTransmittance : mBehind / n);
        passes.surfaces[4 * pixel + 3] = float(showsThrough ? mBehindAlphaSeen / mTransmittance : mBehindAlpha / n);
        passes.shadow[pixel] = float(mShadow / n);
        put(passes.normal, 3 * pixel, mNormal / n);
        for (int c = 0; c < 4; ++c) passes.vector[4 * pixel + c] = float(mVector[c] / n);
        passes.objectIndex[pixel] = float(mObject + 1);
    }

private:
    double mWeight = 0.0;
    Vec3d mCloud{0.0}, mBehindSeen{0.0}, mBehind{0.0}, mNormal{0.0};
    Vec4d mVector{0.0};
    double mCloudAlpha = 0.0, mBehindAlphaSeen = 0.0, mTransmittance = 0.0, mBehindAlpha = 0.0, mShadow = 0.0;
    float mNearest = std::numeric_limits<float>::infinity();
    int mObject = -1;
};

/// One pixel's sums of the beauty's samples that reach it, each weighted by
/// the pixel filter.
struct PixelSums {
    Vec3d colour{0.0};
    double alpha = 0.0;
    double weight = 0.0;

    void add(const CameraSample& seen, double w)
    {
        colour += seen.radiance() * w;
        alpha += seen.alpha() * w;
        weight += w;
    }
    void add(const PixelSums& other)
    {
        colour += other.colour;
        alpha += other.alpha;
        weight += other.weight;
    }
};

/// Allocates every pass of a width x height image.
RenderPasses allocatePasses(int width, int height);

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

/// Camera samples taken together: the same sample of up to
/// SurfaceScene::kPacket neighbouring pixels of a row, so that their rays can
/// be traced as one packet.
struct SamplePacket {
    static constexpr int kSize = SurfaceScene::kPacket;
    int count = 0;                           ///< lanes in use
    std::array<Vec3d, kSize> origins;        ///< the camera's position at each sample's time
    std::array<Vec3d, kSize> dirs;           ///< unit camera directions
    std::array<float, kSize> times{};        ///< in the shutter: 0 at its open, 1 at its close (SurfaceScene's)
    std::array<double, kSize> seconds{};     ///< from the frame's instant (CloudMotion's)
    std::array<SampleRandom, kSize> randoms; ///< each sample's stream, past the pixel jitter's draws
    std::array<uint32_t, kSize> pixels;
};

/// Which pixels stand out after one sample each: where a pixel's first
/// sample and one of its four neighbours' differ by more than threshold in a
/// display value (sRGB-encoded colour, any channel, or coverage), both take
/// the rest of their samples. A flag per pixel, row by row.
std::vector<uint8_t> pixelsThatStandOut(const RenderImage& firstSamples, double threshold);

/// makeSampler() is called once per band of rows (so that it can hold
/// per-thread state such as grid accessors) and returns a callable
/// void(SamplePacket& packet, CameraSample* seen) that fills seen[i] for
/// each lane i < packet.count. A group of pixels' samples come one packet
/// after another: sample 0 of each, then sample 1, and so on. Each sample is
/// shared among the pixels around it by the pixel filter
/// (ImageSettings::pixelFilterWidth), each pixel summing what reaches it in
/// an order that no thread count changes.
///
/// With ImageSettings::adaptiveThreshold above 0, every pixel takes its
/// first sample, and only those that stand out from a neighbour
/// (pixelsThatStandOut, on the first samples before the filter shares them)
/// or that the cloud covers by more than the threshold take the others:
/// their packets hold the block's pixels that do.
template<typename MakePacketSampler>
RenderImage renderCameraPackets(const FrameToRender& f, const MakePacketSampler& makeSampler)
{
    const ImageSettings& settings = f.settings->image;
    const int width = settings.width, height = settings.height, samplesPerPixel = settings.samplesPerPixel;
    const bool adaptive = settings.adaptiveThreshold > 0.0 && samplesPerPixel > 1;
    const bool motionBlur = settings.motionBlur();
    const uint32_t stream = settings.noiseStream(f.frame);
    const PixelFilter filter(settings.pixelFilterWidth);
    const std::size_t pixels = std::size_t(width) * height;
    RenderImage image;
    image.width = width;
    image.height = height;
    image.rgba.assign(pixels * 4, 0.0f);
    image.depth.assign(pixels, std::numeric_limits<float>::infinity());
    const bool passes = f.passes;
    if (passes) image.passes = allocatePasses(width, height);

    // Bands of rows, the same whatever threads take them: each sums into its
    // own rows and, for the rows just above and below it that its samples
    // reach, into its own spare rows, added in band by band after each pass.
    // Packets are whole blocks of kSize columns from the image's left edge:
    // which pixels share a packet can decide which of two triangles an
    // edge's ray hits (the packet's traversal order).
    constexpr int kBandRows = 16;
    const int bands = (height + kBandRows - 1) / kBandRows;
    struct SpareRows {
        std::vector<PixelSums> above, below;
        std::vector<PassSums> passesAbove, passesBelow;
    };
    std::vector<PixelSums> sums(pixels);
    std::vector<PassSums> passSums(passes ? pixels : 0);
    std::vector<SpareRows> spare(filter.spreads() ? bands : 0);
    for (SpareRows& rows : spare) {
        rows.above.resize(width);
        rows.below.resize(width);
        rows.passesAbove.resize(passes ? width : 0);
        rows.passesBelow.resize(passes ? width : 0);
    }
    // With adaptive sampling, each pixel's first sample as taken, and its cloud's cover.
    RenderImage firstSamples;
    std::vector<float> firstCloudCover;
    if (adaptive) {
        firstSamples.width = width;
        firstSamples.height = height;
        firstSamples.rgba.assign(pixels * 4, 0.0f);
        firstCloudCover.assign(pixels, 0.0f);
    }
    const auto screenMotion = [&](const CameraSample& seen, const Vec3d& dir) {
        if (!f.screenMotion) return Vec4d(0.0);
        return seen.object >= 0 ? f.screenMotion->ofPoint(seen.object, seen.objectPosition) : f.screenMotion->ofSky(dir);
    };

    // The second pass visits every band again, taking some of its pixels.
    PixelProgress progress(f.progress, pixels * (adaptive ? 2 : 1));
    // Samples [firstSample, lastSample) of a band's pixels that `take` says (all when null).
    const auto sampleBand = [&](int band, int firstSample, int lastSample, const std::vector<uint8_t>* take) {
        const int y0 = band * kBandRows, y1 = std::min(height, y0 + kBandRows);
        auto sampler = makeSampler();
        SamplePacket packet;
        std::array<CameraSample, SamplePacket::kSize> seen;
        std::array<uint32_t, SamplePacket::kSize> lanePixels;
        std::array<double, SamplePacket::kSize> imageX, imageY; // each lane's sample on the image, in pixels
        Camera moving = f.camera;                               // at a sample's time, when the camera moves over the shutter
        // Shares a sample among the pixels the filter reaches: the band's own or its spare rows.
        const auto share = [&](int lane) {
            const CameraSample& sample = seen[lane];
            const PixelFilter::Span across = filter.along(imageX[lane], width), down = filter.along(imageY[lane], height);
            const Vec4d motion = passes ? screenMotion(sample, packet.dirs[lane]) : Vec4d(0.0);
            for (int j = 0; j < down.count; ++j) {
                const int y = down.first + j;
                for (int i = 0; i < across.count; ++i) {
                    const int x = across.first + i;
                    const double weight = across.weights[i] * down.weights[j];
                    const std::size_t pixel = std::size_t(y) * width + x;
                    const bool own = pixel == lanePixels[lane];
                    if (y >= y0 && y < y1) {
                        sums[pixel].add(sample, weight);
                        if (passes) passSums[pixel].add(sample, motion, weight, own);
                    } else {
                        SpareRows& rows = spare[band];
                        (y < y0 ? rows.above : rows.below)[x].add(sample, weight);
                        if (passes) (y < y0 ? rows.passesAbove : rows.passesBelow)[x].add(sample, motion, weight, own);
                    }
                }
            }
        };
        for (int y = y0; y != y1; ++y)
            for (int x0 = 0; x0 < width; x0 += SamplePacket::kSize) {
                const int x1 = std::min(width, x0 + SamplePacket::kSize);
                packet.count = 0;
                for (int x = x0; x < x1; ++x) {
                    const uint32_t pixel = uint32_t(y) * uint32_t(width) + uint32_t(x);
                    if (!take || (*take)[pixel]) lanePixels[packet.count++] = pixel;
                }
                for (int sample = firstSample; sample < lastSample && packet.count > 0; ++sample) {
                    for (int lane = 0; lane < packet.count; ++lane) {
                        const uint32_t pixel = packet.pixels[lane] = lanePixels[lane];
                        SampleRandom& random = packet.randoms[lane] = SampleRandom(stream, pixel, uint32_t(sample));
                        // One sample at the pixel centre, the rest jittered over it.
                        const double jx = samplesPerPixel == 1 ? 0.5 : random.next();
                        const double jy = samplesPerPixel == 1 ? 0.5 : random.next();
                        const double shutter = motionBlur ? (sample + random.next()) / samplesPerPixel : 0.0;
                        const Camera& camera =
                            f.closingCamera ? (moving = Camera::between(f.camera, *f.closingCamera, shutter)) : f.camera;
                        imageX[lane] = pixel % uint32_t(width) + jx;
                        imageY[lane] = pixel / uint32_t(width) + jy;
                        packet.origins[lane] = camera.position();
                        packet.dirs[lane] = camera.direction(imageX[lane], imageY[lane]);
                        packet.times[lane] = float(shutter);
                        packet.seconds[lane] =
                            (settings.shutterOpen + shutter * (settings.shutterClose - settings.shutterOpen)) * f.secondsPerFrame;
                    }
                    sampler(packet, seen.data());
                    for (int lane = 0; lane < packet.count; ++lane) {
                        const uint32_t pixel = lanePixels[lane];
                        share(lane);
                        if (adaptive && sample == 0) {
                            const Vec3d colour = seen[lane].radiance();
                            float* rgba = &firstSamples.rgba[4 * pixel];
                            for (int c = 0; c < 3; ++c) rgba[c] = float(colour[c]);
                            rgba[3] = float(seen[lane].alpha());
                            firstCloudCover[pixel] = float(1.0 - seen[lane].transmittance);
                        }
                        float& depth = image.depth[pixel];
                        depth = std::min(depth, seen[lane].depth);
                    }
                }
            }
        progress.add(std::size_t(y1 - y0) * width);
    };
    const auto samplePixels = [&](int firstSample, int lastSample, const std::vector<uint8_t>* take) {
        tbb::parallel_for(0, bands, [&](int band) { sampleBand(band, firstSample, lastSample, take); });
        // The spare rows added in, band by band, and emptied for the next pass.
        for (int band = 0; band < int(spare.size()); ++band) {
            SpareRows& rows = spare[band];
            const int y0 = band * kBandRows, y1 = std::min(height, y0 + kBandRows);
            for (const auto& [y, row, passRow] :
                 {std::tuple(y0 - 1, &rows.above, &rows.passesAbove), std::tuple(y1, &rows.below, &rows.passesBelow)}) {
                if (y < 0 || y >= height) continue;
                for (int x = 0; x < width; ++x) {
                    const std::size_t pixel = std::size_t(y) * width + x;
                    sums[pixel].add((*row)[x]);
                    if (passes) passSums[pixel].add((*passRow)[x]);
                }
            }
            rows.above.assign(rows.above.size(), PixelSums());
            rows.below.assign(rows.below.size(), PixelSums());
            rows.passesAbove.assign(rows.passesAbove.size(), PassSums());
            rows.passesBelow.assign(rows.passesBelow.size(), PassSums());
        }
    };

    if (!adaptive) {
        samplePixels(0, samplesPerPixel, nullptr);
    } else {
        samplePixels(0, 1, nullptr);
        std::vector<uint8_t> refined = pixelsThatStandOut(firstSamples, settings.adaptiveThreshold);
        // The cloud's pixels take every sample whatever their neighbours:
        // left to its noise, which of them took one and which all changed
        // from frame to frame with the slightest change of the cloud, and a
        // cloud that barely moved boiled.
        for (std::size_t pixel = 0; pixel < refined.size(); ++pixel)
            if (firstCloudCover[pixel] > settings.adaptiveThreshold) refined[pixel] = 1;
        samplePixels(1, samplesPerPixel, &refined);
    }
    tbb::parallel_for(0, height, [&](int y) {
        for (std::size_t pixel = std::size_t(y) * width; pixel < std::size_t(y + 1) * width; ++pixel) {
            const PixelSums& sum = sums[pixel];
            float* out = &image.rgba[4 * pixel];
            for (int c = 0; c < 3; ++c) out[c] = float(sum.colour[c] / sum.weight);
            out[3] = float(sum.alpha / sum.weight);
            if (passes) passSums[pixel].write(image.passes, pixel);
        }
    });
    return image;
}

/// One camera ray of a SamplePacket.
struct CameraRay {
    Vec3d origin, dir;
    float time;     ///< SamplePacket::times
    double seconds; ///< SamplePacket::seconds
};

/// renderCameraPackets for a sampler of one sample at a time:
/// makeSampler() returns a callable
/// CameraSample(const CameraRay& ray, SampleRandom& random, uint32_t pixel).
template<typename MakeSampler>
RenderImage renderCameraSamples(const FrameToRender& f, const MakeSampler& makeSampler)
{
    return renderCameraPackets(f, [&] {
        return [sampler = makeSampler()](SamplePacket& packet, CameraSample* seen) mutable {
            for (int lane = 0; lane < packet.count; ++lane) {
                const CameraRay ray{packet.origins[lane], packet.dirs[lane], packet.times[lane], packet.seconds[lane]};
                seen[lane] = sampler(ray, packet.randoms[lane], packet.pixels[lane]);
            }
        };
    });
}

} // namespace vfield
