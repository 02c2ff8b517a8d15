#pragma once
/// @file cloud_lighting.h
/// A frame's density grid (world space) and the light that reaches into it,
/// computed once per frame: where surfaces block the sun, on a grid over the
/// cloud's box (coarser than the density); and, for surfaces, the cloud's
/// optical depth towards the sun on a lattice aligned with the sun's rays,
/// fine across them, so that a cloud's shadow is as sharp as its density.
/// Shared by the back-ends: vfield's renderer shades with it (the cloud's own
/// samples take the light through the cloud from OpticalDepthMap), the
/// POV-Ray export writes the sky-lit density from it.

#include <vfield/core/dense_grid.h>
#include <vfield/core/vdb_trees.h>
#include <vfield/render/render_settings.h>

#include <functional>

namespace vfield {

class CloudLighting {
public:
    /// Whether a surface blocks the sun from origin along dir (unit).
    using Occlusion = std::function<bool(const Vec3d& origin, const Vec3d& dir)>;

    /// toSun points towards the sun. sunBlocked may be empty: then only the
    /// cloud itself shadows it.
    CloudLighting(openvdb::FloatGrid::ConstPtr density, const MediumSettings& medium, const Vec3d& toSun,
                  const Occlusion& sunBlocked);

    /// No density, or no extinction: nothing to light or draw.
    bool empty() const { return mEmpty; }
    const openvdb::FloatGrid& density() const { return *mDensity; }
    const openvdb::FloatGrid::ConstPtr& densityPtr() const { return mDensity; }
    /// The box of the active voxels' extents, one voxel wider so that
    /// trilinear reads fade to zero inside it.
    const BBoxd& bounds() const { return mBounds; }
    const Vec3d& toSun() const { return mToSun; }

    /// Where the ray origin + t dir (dir unit) is inside bounds() grown by
    /// `grow` on every side, narrowing [tMin, tMax]; false if it misses.
    bool clip(const Vec3d& origin, const Vec3d& dir, double& tMin, double& tMax, double grow = 0.0) const;

    /// Transmittance of the cloud alone from p towards the sun (1 where no
    /// cloud is in the way), for surfaces: their shadows from other surfaces
    /// come from their own shadow rays, so a surface beside a shadowed grid
    /// point is not darkened by interpolation. Read from the sun-aligned
    /// depth map, whatever the light grids' cells: read from those on a face
    /// of a large box (a cloud with a stray wisp far away), a small cloud's
    /// shadow would come out as nested squares of their size.
    double sunTransmittance(const Vec3d& p) const;
    /// The share of the sun no surface blocks at a point of the cloud, read
    /// trilinearly from its grid, unclamped.
    float sunVisible(const Vec3d& p) const { return mSunVisible.at(p); }

    /// Density x the sky's transmittance down to each voxel: where the cloud
    /// scatters the sky's light, and how much (same voxels as the density).
    /// Marched through the light grid's coarse density on each call: only
    /// the POV-Ray export asks, once a frame (vfield's renderer takes the
    /// sky's light from an OpticalDepthMap).
    openvdb::FloatGrid::Ptr skyLitDensity() const;

private:
    /// Optical depth from a point towards the sun at the points of a lattice
    /// aligned with the sun: columns across the sun's rays (axes `across1`,
    /// `across2`, perpendicular to it, from `acrossMin`) and slices along them,
    /// down from the box's point nearest the sun (`top`, along toSun from
    /// `centre`). Depth accumulates smoothly along a ray, so slices are coarse
    /// and columns fine.
    struct SunDepth {
        Vec3d centre{0.0}, across1{1, 0, 0}, across2{0, 0, 1};
        double acrossMin1 = 0.0, acrossMin2 = 0.0, top = 0.0;
        double inverseAcross = 1.0, inverseAlong = 1.0;
        DenseGrid depth; ///< lattice coordinates: (column, column, slice)

        double at(const Vec3d& p, const Vec3d& toSun) const;
    };

    /// The density box-filtered onto the light grid's cells (mVoxelsPerCell
    /// voxels each from mFirstVoxel), values at their centres.
    DenseGrid lightGridDensity() const;
    /// The depth map marched through `density` (a coarse density).
    SunDepth sunDepthTowardsSun(const DenseGrid& density) const;
    /// The cloud's transmittance towards a light (unit direction) at the
    /// points of the light grid, through the coarse density (cell-centred on it).
    DenseGrid transmittanceTowards(const DenseGrid& coarse, const Vec3d& towards) const;

    openvdb::FloatGrid::ConstPtr mDensity;
    DenseGrid mSunVisible;
    openvdb::Coord mFirstVoxel; ///< the lower corner of the light grid's first cell
    int mVoxelsPerCell = 2;     ///< the light grid's cell, density voxels
    SunDepth mSunDepth;
    BBoxd mBounds;
    Vec3d mToSun;
    double mExtinction;
    bool mEmpty = true;
};

} // namespace vfield
