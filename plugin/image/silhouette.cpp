#include <vfield/image/silhouette.h>

#include <vfield/core/error.h>
#include <vfield/core/image_file.h>

#include <algorithm>
#include <cmath>

namespace vfield {

SilhouetteMeasure measureSilhouette(const std::vector<uint8_t>& mask, int width, int height, const SilhouetteOptions& options)
{
    const auto isPowerOfTwo = [](int n) { return n > 0 && (n & (n - 1)) == 0; };
    if (!isPowerOfTwo(options.smallestBox) || !isPowerOfTwo(options.largestBox) || options.largestBox <= options.smallestBox)
        throw ValueError("silhouette box sizes must be powers of two, the smallest below the largest");
    if (mask.size() != std::size_t(width) * std::size_t(height)) throw ValueError("the mask is not width x height");

    const auto cloud = [&](int x, int y) { return mask[std::size_t(y) * std::size_t(width) + std::size_t(x)] != 0; };
    std::vector<uint8_t> boundary(mask.size(), 0);
    SilhouetteMeasure measure;
    long long cloudPixels = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            if (!cloud(x, y)) continue;
            ++cloudPixels;
            const bool edge = (x > 0 && !cloud(x - 1, y)) || (x + 1 < width && !cloud(x + 1, y)) || (y > 0 && !cloud(x, y - 1)) ||
                              (y + 1 < height && !cloud(x, y + 1));
            if (edge) {
                boundary[std::size_t(y) * std::size_t(width) + std::size_t(x)] = 1;
                ++measure.boundaryPixels;
            }
        }
    measure.coverage = mask.empty() ? 0.0 : double(cloudPixels) / double(mask.size());

    for (int s = options.smallestBox; s <= options.largestBox; s *= 2) {
        const int columns = (width + s - 1) / s, rows = (height + s - 1) / s;
        std::vector<uint8_t> hit(std::size_t(columns) * std::size_t(rows), 0);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                if (boundary[std::size_t(y) * std::size_t(width) + std::size_t(x)])
                    hit[std::size_t(y / s) * std::size_t(columns) + std::size_t(x / s)] = 1;
        measure.boxCounts.emplace_back(s, std::count(hit.begin(), hit.end(), uint8_t(1)));
    }

    // Least squares of log N against log(1 / s), over the sizes that hold any boundary.
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [s, count] : measure.boxCounts) {
        if (count == 0) continue;
        const double x = -std::log(double(s)), y = std::log(double(count));
        n += 1;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    const double denominator = n * sxx - sx * sx;
    measure.dimension = n >= 2 && denominator > 0.0 ? (n * sxy - sx * sy) / denominator : 0.0;
    return measure;
}

SilhouetteMeasure measureSilhouette(const std::string& withCloud, const std::string& withoutCloud,
                                    const SilhouetteOptions& options)
{
    const OIIO::ImageBuf a = readImageAsFloat(withCloud), b = readImageAsFloat(withoutCloud);
    const OIIO::ImageSpec &sa = a.spec(), &sb = b.spec();
    if (sa.width != sb.width || sa.height != sb.height)
        throw ValueError(withCloud + " is " + std::to_string(sa.width) + "x" + std::to_string(sa.height) + " but " +
                         withoutCloud + " is " + std::to_string(sb.width) + "x" + std::to_string(sb.height));
    const int channels = std::min({sa.nchannels, sb.nchannels, 3});
    std::vector<float> pa(std::size_t(sa.width) * sa.height * sa.nchannels), pb(std::size_t(sb.width) * sb.height * sb.nchannels);
    a.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, pa.data());
    b.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, pb.data());
    std::vector<uint8_t> mask(std::size_t(sa.width) * std::size_t(sa.height), 0);
    for (std::size_t i = 0; i < mask.size(); ++i)
        for (int c = 0; c < channels; ++c)
            if (pa[i * sa.nchannels + c] - pb[i * sb.nchannels + c] > options.threshold) mask[i] = 1;
    return measureSilhouette(mask, sa.width, sa.height, options);
}

SilhouetteMeasure measureOpacitySilhouette(const std::string& frame, const SilhouetteOptions& options)
{
    const OIIO::ImageBuf image = readImageAsFloat(frame);
    const OIIO::ImageSpec& spec = image.spec();
    if (spec.alpha_channel < 0) throw ValueError(frame + " has no alpha channel (render it as EXR with render.transparentSky)");
    std::vector<float> alpha(std::size_t(spec.width) * std::size_t(spec.height));
    image.get_pixels(OIIO::ROI(0, spec.width, 0, spec.height, 0, 1, spec.alpha_channel, spec.alpha_channel + 1),
                     OIIO::TypeDesc::FLOAT, alpha.data());
    std::vector<uint8_t> mask(alpha.size(), 0);
    for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = alpha[i] > options.threshold;
    return measureSilhouette(mask, spec.width, spec.height, options);
}

} // namespace vfield
