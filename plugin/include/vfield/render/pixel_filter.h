#pragma once
/// @file pixel_filter.h
/// How a camera sample's light is shared among the pixels around it
/// (ImageSettings::pixelFilterWidth). A box keeps every sample in its own
/// pixel, so a pixel is the mean of its few samples alone: as a cloud's fine
/// detail shifts under them from frame to frame, that mean jumps, and the
/// cloud boils at the pixel. A Gaussian spreads each sample over the pixels
/// whose centres lie within half its width, weighted by its distance from
/// them (pbrt-v4's GaussianFilter, with the width of Arnold's, RenderMan's and
/// Mantra's default 2x2 Gaussian), so every pixel averages its neighbours'
/// nearby samples as well as its own.

#include <array>

namespace vfield {

class PixelFilter {
public:
    /// The widest filter: a sample reaches at most the pixel on either side
    /// of its own.
    static constexpr double kMaxWidth = 3.0;

    /// width: 0 for a box; otherwise from 1 to kMaxWidth pixels, the
    /// Gaussian's standard deviation a quarter of it (0.5 pixels at width 2),
    /// less its value at half the width so that it falls to 0 there.
    explicit PixelFilter(double width);

    /// The pixels a sample reaches along one axis: `count` of them from
    /// `first`, with their weights.
    struct Span {
        int first = 0;
        int count = 0;
        std::array<double, 3> weights{};
    };

    /// The span of a sample at `position` (pixels from the image's edge;
    /// pixel i's centre is at i + 0.5) on an axis of `pixels` pixels: those
    /// off the image are left out.
    Span along(double position, int pixels) const;

    /// Whether samples reach pixels beyond their own.
    bool spreads() const { return mRadius > 0.0; }

private:
    double weight(double offset) const;

    double mRadius = 0.0; ///< 0 for a box
    double mInverseTwoSigmaSquared = 0.0;
    double mEdgeValue = 0.0;
};

} // namespace vfield
