#pragma once
/// @file dense_grid.h
/// Float values at the points origin + spacing (i, j, k) of a box-shaped
/// lattice, x fastest, read trilinearly: for fields that fill their box (a
/// frame's light transmittance, a box-filtered density), where a plain array
/// read costs a fraction of a sparse tree's.

#include <vfield/core/math.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vfield {

/// Points of a lattice every `spacing` over a box of these extents, corners included.
inline std::array<int, 3> latticePoints(const Vec3d& extent, double spacing)
{
    return {int(std::ceil(extent[0] / spacing)) + 1, int(std::ceil(extent[1] / spacing)) + 1,
            int(std::ceil(extent[2] / spacing)) + 1};
}

/// The lattice every `spacing` anchored at the world's origin: the index,
/// per axis, of its last point at or below p. A lattice from there stays put
/// while the box it covers changes.
inline std::array<int64_t, 3> anchoredIndexBelow(const Vec3d& p, double spacing)
{
    return {int64_t(std::floor(p[0] / spacing)), int64_t(std::floor(p[1] / spacing)), int64_t(std::floor(p[2] / spacing))};
}

/// How many values a lattice (or grid of cells) of these counts along x, y and z holds.
inline std::size_t latticeSize(const std::array<int, 3>& counts)
{
    return std::size_t(counts[0]) * std::size_t(counts[1]) * std::size_t(counts[2]);
}

class DenseGrid {
public:
    DenseGrid() = default;
    /// All points set to `fill`; reads beyond the lattice give `outside`.
    DenseGrid(const Vec3d& origin, double spacing, const std::array<int, 3>& points, float fill, float outside)
        : mOrigin(origin), mInverseSpacing(1.0 / spacing), mSpacing(spacing), mPoints(points), mValues(latticeSize(points), fill),
          mOutside(outside)
    {}

    const Vec3d& origin() const { return mOrigin; }
    double spacing() const { return mSpacing; }
    const std::array<int, 3>& points() const { return mPoints; }
    std::size_t size() const { return mValues.size(); }

    std::size_t index(int i, int j, int k) const
    {
        return (std::size_t(k) * std::size_t(mPoints[1]) + std::size_t(j)) * std::size_t(mPoints[0]) + std::size_t(i);
    }
    /// The lattice point of a linear index.
    std::array<int, 3> point(std::size_t n) const
    {
        return {int(n % std::size_t(mPoints[0])), int(n / std::size_t(mPoints[0]) % std::size_t(mPoints[1])),
                int(n / (std::size_t(mPoints[0]) * std::size_t(mPoints[1])))};
    }
    Vec3d position(int i, int j, int k) const { return mOrigin + Vec3d(i, j, k) * mSpacing; }
    float& operator[](std::size_t n) { return mValues[n]; }
    float operator[](std::size_t n) const { return mValues[n]; }

    /// Trilinear between lattice points; points beyond the lattice read `outside`.
    float at(const Vec3d& p) const
    {
        const Vec3d u = (p - mOrigin) * mInverseSpacing;
        const double fi = std::floor(u[0]), fj = std::floor(u[1]), fk = std::floor(u[2]);
        const int i = int(fi), j = int(fj), k = int(fk);
        const float fx = float(u[0] - fi), fy = float(u[1] - fj), fz = float(u[2] - fk);
        const bool inside = i >= 0 && j >= 0 && k >= 0 && i + 1 < mPoints[0] && j + 1 < mPoints[1] && k + 1 < mPoints[2];
        float corner[8];
        if (inside) { // the common case: eight reads, no bounds checks
            const std::size_t n = index(i, j, k), dy = std::size_t(mPoints[0]), dz = dy * std::size_t(mPoints[1]);
            corner[0] = mValues[n];
            corner[1] = mValues[n + 1];
            corner[2] = mValues[n + dy];
            corner[3] = mValues[n + dy + 1];
            corner[4] = mValues[n + dz];
            corner[5] = mValues[n + dz + 1];
            corner[6] = mValues[n + dz + dy];
            corner[7] = mValues[n + dz + dy + 1];
        } else {
            for (int c = 0; c < 8; ++c) {
                const int x = i + (c & 1), y = j + ((c >> 1) & 1), z = k + (c >> 2);
                const bool within = x >= 0 && y >= 0 && z >= 0 && x < mPoints[0] && y < mPoints[1] && z < mPoints[2];
                corner[c] = within ? mValues[index(x, y, z)] : mOutside;
            }
        }
        const float x0 = corner[0] + (corner[1] - corner[0]) * fx, x1 = corner[2] + (corner[3] - corner[2]) * fx;
        const float x2 = corner[4] + (corner[5] - corner[4]) * fx, x3 = corner[6] + (corner[7] - corner[6]) * fx;
        const float y0 = x0 + (x1 - x0) * fy, y1 = x2 + (x3 - x2) * fy;
        return y0 + (y1 - y0) * fz;
    }

    /// visit(index, weight) for the eight points a trilinear read at p
    /// weighs, with their weights (summing to one); p beyond the lattice is
    /// taken at its nearest point inside. What spreads a value over the
    /// lattice so that reads give it back.
    template<typename Visit>
    void forCorners(const Vec3d& p, const Visit& visit) const
    {
        const Vec3d u = (p - mOrigin) * mInverseSpacing;
        std::array<int, 3> cell;
        std::array<double, 3> fraction;
        for (int axis = 0; axis < 3; ++axis) {
            cell[axis] = std::clamp(int(std::floor(u[axis])), 0, std::max(0, mPoints[axis] - 2));
            fraction[axis] = mPoints[axis] < 2 ? 0.0 : std::clamp(u[axis] - cell[axis], 0.0, 1.0);
        }
        for (int corner = 0; corner < 8; ++corner) {
            double weight = 1.0;
            std::array<int, 3> at;
            for (int axis = 0; axis < 3; ++axis) {
                const bool upper = (corner >> axis) & 1;
                at[axis] = cell[axis] + (upper && mPoints[axis] > 1);
                weight *= upper ? fraction[axis] : 1.0 - fraction[axis];
            }
            if (weight > 0.0) visit(index(at[0], at[1], at[2]), weight);
        }
    }

private:
    Vec3d mOrigin{0.0};
    double mInverseSpacing = 1.0, mSpacing = 1.0;
    std::array<int, 3> mPoints{0, 0, 0};
    std::vector<float> mValues;
    float mOutside = 0.0f;
};

} // namespace vfield
