#include <vfield/render/embree/scattered_light.h>

#include "paths.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

namespace vfield {

namespace {

/// Which of the 2n + 1 streams of paths a frame draws from (n: pathFramesAround).
int pathStream(const FrameToRender& f, int frame)
{
    const int streams = 2 * f.settings->integrator.multipleScattering.pathFramesAround + 1;
    return (frame % streams + streams) % streams;
}

/// The grid the paths' camera rays are cast on, one jittered ray a cell:
/// square cells on a lattice anchored at the image's corner, in units of the
/// image's height (a preview's lattice is the final frame's), about `rays`
/// of them over the region where the cloud's box is, their size rounded to
/// a power of the square root of 2. So the cells stay where they are while
/// the box changes from frame to frame, and so do the rays cast through them
/// (each drawn by its cell's key, its place in the whole image's lattice): a
/// grid stretched over the box moved every ray whenever the box moved, and
/// the light gathered from the paths of neighbouring frames boiled.
class RayLattice {
public:
    RayLattice(const ImageRegion& region, int width, int height, double rays) : mHeight(height)
    {
        const double area = region.width() * region.height() / (double(height) * height);
        mCell = std::exp2(std::round(2.0 * std::log2(std::sqrt(area / rays))) / 2.0);
        mStride = int(std::ceil(double(width) / height / mCell)) + 1;
        mColumn0 = cellOf(region.x0);
        mRow0 = cellOf(region.y0);
        mColumns = cellOf(region.x1) - mColumn0 + 1;
        mRows = cellOf(region.y1) - mRow0 + 1;
    }
    std::size_t size() const { return std::size_t(mColumns) * std::size_t(mRows); }
    int columns() const { return mColumns; }
    int rows() const { return mRows; }
    /// The column (row) of the cells over the region that image x (y), in pixels, falls in.
    int columnAt(double x) const { return std::clamp(cellOf(x) - mColumn0, 0, mColumns - 1); }
    int rowAt(double y) const { return std::clamp(cellOf(y) - mRow0, 0, mRows - 1); }
    /// Cell n's key, the same in every frame whatever the region.
    uint32_t key(std::size_t n) const
    {
        return uint32_t(std::size_t(rowOf(n)) * std::size_t(mStride) + std::size_t(columnOf(n)));
    }
    /// Cell n's rank in [0, 1): as Roberts's R2 sequence ranks the cells of
    /// an image for dithering, so that the cells under any rank are spread
    /// evenly over the image, in every frame alike.
    double rank(std::size_t n) const
    {
        const double r = 0.7548776662466927 * columnOf(n) + 0.5698402909980532 * rowOf(n);
        return r - std::floor(r);
    }
    /// The point (u, v) in [0, 1)^2 of cell n, in pixels.
    Vec2d point(std::size_t n, double u, double v) const
    {
        const double column = double(mColumn0) + double(n % std::size_t(mColumns)) + u;
        const double row = double(mRow0) + double(n / std::size_t(mColumns)) + v;
        return Vec2d(column * mCell * mHeight, row * mCell * mHeight);
    }

private:
    int cellOf(double pixels) const { return int(std::floor(pixels / mHeight / mCell)); }
    /// Cell n's column and row in the whole image's lattice.
    int columnOf(std::size_t n) const { return mColumn0 + int(n % std::size_t(mColumns)); }
    int rowOf(std::size_t n) const { return mRow0 + int(n / std::size_t(mColumns)); }

    double mHeight, mCell = 1.0;
    int mStride = 1, mColumn0 = 0, mRow0 = 0, mColumns = 1, mRows = 1;
};

/// The cells, of those whose rays scattered, whose paths go on: the
/// `count` of lowest rank (RayLattice::rank), in the lattice's order: spread
/// evenly over them. A cloud that changes a little changes which rays
/// scatter a little, and which go on as little; a shifted choice (every
/// k-th) traced other paths everywhere.
template<typename Cast>
std::vector<std::size_t> thinnedEvenly(const std::vector<std::optional<Cast>>& cast, const RayLattice& lattice, std::size_t count)
{
    std::vector<double> ranks;
    for (std::size_t n = 0; n < cast.size(); ++n)
        if (cast[n]) ranks.push_back(lattice.rank(n));
    double below = 2.0; // all of them
    if (ranks.size() > count) {
        std::nth_element(ranks.begin(), ranks.begin() + std::ptrdiff_t(count), ranks.end());
        below = ranks[count];
    }
    std::vector<std::size_t> going;
    for (std::size_t n = 0; n < cast.size(); ++n)
        if (cast[n] && lattice.rank(n) < below) going.push_back(n);
    return going;
}

} // namespace

ScatteredPaths traceScatteredPaths(const FrameToRender& f)
{
    const CloudLighting& lighting = f.volume->lighting();
    const MultipleScatteringSettings& settings = f.settings->integrator.multipleScattering;
    const BBoxd& box = lighting.bounds();
    ScatteredPaths traced;
    traced.frame = f.frame;
    if (f.settings->integrator.maxBounces <= 1) return traced; // single scattering only: nothing more to add

    // The reference's own camera paths, on a jittered grid over the part of
    // the image where the cloud's box is: each goes to its first scattering
    // in the cloud by delta tracking, where the march's samples weigh the
    // cloud (transmittance x extinction), and on from there as the
    // reference's paths go; what it carries back from its later vertices is
    // the light the march needs at that point. Finding where a ray scatters
    // costs a fraction of the path that follows: kRaysPerPath x pathsPerFrame
    // rays are cast, and at most pathsPerFrame of those that scatter, evenly
    // spread over them, go on. Their number does not depend on the image's
    // resolution: a preview's lattice is the final frame's.
    constexpr int kRaysPerPath = 4; // 56 bytes a ray: 224 MB at most (pathsPerFrame <= 1e6)
    const ImageRegion region = f.camera.regionOf(box);
    if (region.empty()) return traced;
    const std::size_t paths = std::size_t(settings.pathsPerFrame);
    const RayLattice lattice(region, f.settings->image.width, f.settings->image.height, double(kRaysPerPath) * double(paths));
    struct FirstScattering {
        Vec3d direction, position;
    };
    std::vector<std::optional<FirstScattering>> cast(lattice.size());
    // The grid's cells that some of the density's leaves or tiles (with the
    // voxel around them that trilinear reads reach) cover on the image: a
    // ray through any other cell meets no cloud and is not cast. Most rays
    // over a cloud's box miss the cloud, and delta tracking walked each
    // across the whole box.
    std::vector<char> covered(cast.size(), 0);
    {
        const openvdb::FloatGrid& density = lighting.density();
        const auto cover = [&](const openvdb::CoordBBox& voxels) {
            const BBoxd world(density.indexToWorld(voxels.min().asVec3d() - Vec3d(1.0)),
                              density.indexToWorld(voxels.max().asVec3d() + Vec3d(1.0)));
            const ImageRegion seen = f.camera.regionOf(world);
            if (seen.empty()) return;
            const int i0 = lattice.columnAt(seen.x0), i1 = lattice.columnAt(seen.x1);
            for (int j = lattice.rowAt(seen.y0); j <= lattice.rowAt(seen.y1); ++j)
                std::fill_n(covered.begin() + std::ptrdiff_t(j) * lattice.columns() + i0, i1 - i0 + 1, 1);
        };
        for (auto leaf = density.tree().cbeginLeaf(); leaf; ++leaf) cover(leaf->getNodeBoundingBox());
        auto tile = density.tree().cbeginValueOn();
        tile.setMaxDepth(openvdb::FloatTree::ValueOnCIter::LEAF_DEPTH - 1);
        for (; tile; ++tile) cover(tile.getBoundingBox());
    }
    // The frame's instant: under motion blur, the march reads the lattice
    // where the motion brought each sample from.
    const Medium medium(f.volume, f.settings->medium, nullptr);
    // Streams apart from the camera's (seed, pixel, sample) ones, and one for
    // each of any 2n + 1 frames in a row whose paths a lattice gathers
    // (pathFramesAround n): a cloud that holds still gathers the same paths
    // in every frame.
    const uint32_t stream =
        (f.settings->image.noiseStream(f.frame) ^ 0x9e3779b9u) + uint32_t(pathStream(f, f.frame)) * 0x85ebca6bu;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cast.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        Medium::Density density = medium.density();
        for (std::size_t n = r.begin(); n != r.end(); ++n) {
            if (!covered[n]) continue;
            SampleRandom random(stream, lattice.key(n), 0u);
            const double u = random.next(), v = random.next();
            const Vec2d pixel = lattice.point(n, u, v);
            const Vec3d origin = f.camera.position(), dir = f.camera.direction(pixel[0], pixel[1]);
            // A surface is looked for only before a collision, as the reference's paths do (nextEvent).
            const std::optional<double> scatter = medium.collision(density, nullptr, origin, dir, 0.0, kInfinity, random);
            if (scatter && !f.surfaces->occluded(origin, dir, 0.0, *scatter))
                cast[n] = FirstScattering{dir, origin + dir * *scatter};
        }
    });
    const std::vector<std::size_t> going = thinnedEvenly(cast, lattice, paths);
    // The velocity grid covers the density's voxels only: read as it is, a
    // path at the cloud's edge, where most first scatter, would find the
    // velocity halved by the empty voxels beside it. CloudMotion extends it
    // as far as the paths are moved: 2n frames, at the scene's ends.
    std::optional<CloudMotion> velocity;
    if (f.velocity && settings.pathFramesAround > 0)
        velocity.emplace(*f.velocity, 2.0 * settings.pathFramesAround * f.secondsPerFrame);
    traced.paths.resize(going.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, going.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
        PathTracer tracer(f, medium, PathTracer::SunThroughCloud::AsTheMarch);
        std::optional<CloudMotion::Instant> velocityAt;
        if (velocity) velocityAt.emplace(*velocity, 0.0);
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            const FirstScattering& cameraRay = *cast[going[k]];
            ScatteredPaths::Path& path = traced.paths[k];
            path.position = cameraRay.position;
            if (velocityAt) path.velocity = velocityAt->velocity(path.position);
            SampleRandom random(stream, lattice.key(going[k]), 1u);
            path.light = tracer.radiance(path.position, tracer.scatteredDirection(cameraRay.direction, random),
                                         PathTracer::Start::Scattered, random);
        }
    });
    return traced;
}

ScatteredLightGrid gatherScatteredLight(const FrameToRender& f, const std::vector<const ScatteredPaths*>& traced)
{
    // Three colour channels a point, 192 MiB.
    constexpr std::size_t kMaxLatticePoints = std::size_t(1) << 24;
    const CloudLighting& lighting = f.volume->lighting();
    const BBoxd& box = lighting.bounds();
    // The lattice's points lie on multiples of the spacing, wherever the
    // cloud's box is: anchored at the box's corner, they moved whenever the
    // box did, each point took other paths' light, and the light boiled from
    // frame to frame.
    double spacing = f.settings->integrator.multipleScattering.pathSpacing * lighting.density().voxelSize()[0];
    const auto corner = [&] {
        const std::array<int64_t, 3> first = anchoredIndexBelow(box.min(), spacing);
        return Vec3d(double(first[0]), double(first[1]), double(first[2])) * spacing;
    };
    const auto pointsFor = [&] { return latticePoints(box.max() - corner(), spacing); };
    while (latticeSize(pointsFor()) > kMaxLatticePoints) spacing *= 1.25; // coarser, within budget
    const std::array<int, 3> points = pointsFor();
    ScatteredLightGrid grid;
    for (DenseGrid& channel : grid.rgb) channel = DenseGrid(corner(), spacing, points, 0.0f, 0.0f);
    const DenseGrid& lattice = grid.rgb[0];

    // Each lattice point takes the mean of the paths' light weighted as a
    // trilinear read there would weigh it. The march reads the lattice where
    // camera rays scatter, as often as the paths scattered there (its samples
    // weigh the cloud as delta tracking does), so over the image its reads
    // come to the paths' mean however coarse the lattice. Points that traced
    // their own paths, interpolated, come out dark on a coarse lattice, the
    // light's rise inside the lit surface cut across. Another frame's path
    // is moved to where the cloud carries its point by this frame's instant,
    // and left out when that falls outside this frame's box. The sums go into
    // the grid, then become means.
    std::vector<float> weights(lattice.size(), 0.0f);
    std::vector<const ScatteredPaths*> byStream = traced;
    std::stable_sort(byStream.begin(), byStream.end(), [&](const ScatteredPaths* a, const ScatteredPaths* b) {
        return pathStream(f, a->frame) < pathStream(f, b->frame);
    });
    for (const ScatteredPaths* frame : byStream) {
        const double seconds = double(f.frame - frame->frame) * f.secondsPerFrame;
        for (const ScatteredPaths::Path& path : frame->paths) {
            const Vec3d position = path.position + path.velocity * seconds;
            if (!box.isInside(position)) continue;
            lattice.forCorners(position, [&](std::size_t n, double weight) {
                weights[n] += float(weight);
                for (int c = 0; c < 3; ++c) grid.rgb[c][n] += float(weight * path.light[c]);
            });
        }
    }
    // A point no path came near takes its neighbours' mean: where the cloud
    // is thin few paths scatter, and a point left at zero darkened the reads
    // beside it. Such points are written and only the others read.
    const auto channels = [&](std::size_t n) { return Vec3d(grid.rgb[0][n], grid.rgb[1][n], grid.rgb[2][n]); };
    tbb::parallel_for(std::size_t(0), lattice.size(), [&](std::size_t n) {
        if (weights[n] > 0.0f) return;
        Vec3d sum(0.0);
        double weight = 0.0;
        const std::array<int, 3> ijk = lattice.point(n);
        for (int neighbour = 0; neighbour < 27; ++neighbour) {
            const int i = ijk[0] + neighbour % 3 - 1, j = ijk[1] + neighbour / 3 % 3 - 1, k = ijk[2] + neighbour / 9 - 1;
            if (i < 0 || j < 0 || k < 0 || i >= points[0] || j >= points[1] || k >= points[2]) continue;
            const std::size_t m = lattice.index(i, j, k);
            if (weights[m] == 0.0f) continue;
            weight += weights[m];
            sum += channels(m);
        }
        if (weight > 0.0)
            for (int c = 0; c < 3; ++c) grid.rgb[c][n] = float(sum[c] / weight);
    });
    tbb::parallel_for(std::size_t(0), lattice.size(), [&](std::size_t n) {
        if (weights[n] > 0.0f)
            for (int c = 0; c < 3; ++c) grid.rgb[c][n] /= weights[n];
    });
    return grid;
}

} // namespace vfield
