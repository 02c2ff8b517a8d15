#include <vfield/render/pixel_filter.h>

#include <algorithm>
#include <cmath>

namespace vfield {

PixelFilter::PixelFilter(double width)
{
    if (width <= 0.0) return;
    mRadius = 0.5 * std::min(width, kMaxWidth);
    const double sigma = 0.5 * mRadius;
    mInverseTwoSigmaSquared = 1.0 / (2.0 * sigma * sigma);
    mEdgeValue = std::exp(-mRadius * mRadius * mInverseTwoSigmaSquared);
}

double PixelFilter::weight(double offset) const
{
    return std::max(0.0, std::exp(-offset * offset * mInverseTwoSigmaSquared) - mEdgeValue);
}

PixelFilter::Span PixelFilter::along(double position, int pixels) const
{
    const int own = std::clamp(int(std::floor(position)), 0, pixels - 1);
    Span span;
    if (!spreads()) {
        span.first = own;
        span.count = 1;
        span.weights[0] = 1.0;
        return span;
    }
    span.first = std::max(own - 1, 0);
    for (int pixel = span.first; pixel <= std::min(own + 1, pixels - 1); ++pixel)
        span.weights[std::size_t(span.count++)] = weight(pixel + 0.5 - position);
    return span;
}

} // namespace vfield
