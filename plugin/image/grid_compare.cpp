#include <vfield/image/grid_compare.h>

#include <vfield/core/vdb_file.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace vfield {

namespace {

double difference(float a, float b) { return std::abs(double(a) - double(b)); }
double difference(const openvdb::Vec3s& a, const openvdb::Vec3s& b) { return (openvdb::Vec3d(a) - openvdb::Vec3d(b)).length(); }

/// Every voxel active in `from` (tiles by all their voxels) against `to`;
/// with skipShared, only those `to` does not hold active.
template<typename GridT>
void compareActiveVoxels(const GridT& from, const GridT& to, bool skipShared, double tolerance, GridDifference& result)
{
    auto other = to.getConstAccessor();
    for (auto it = from.cbeginValueOn(); it; ++it) {
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        for (auto c = box.begin(); c; ++c) {
            const bool shared = other.isValueOn(*c);
            if (shared && skipShared) continue;
            const double d = difference(*it, other.getValue(*c));
            ++result.voxels;
            result.maxDifference = std::max(result.maxDifference, d);
            if (!shared || d > tolerance) ++result.differing;
        }
    }
}

template<typename GridT>
void compareVoxels(const GridT& a, const GridT& b, double tolerance, GridDifference& result)
{
    compareActiveVoxels(a, b, false, tolerance, result);
    compareActiveVoxels(b, a, true, tolerance, result);
}

} // namespace

bool GridComparison::equal() const
{
    return onlyInA.empty() && onlyInB.empty() &&
           std::all_of(grids.begin(), grids.end(), [](const GridDifference& g) { return g.differing == 0; });
}

GridComparison compareGridFiles(const std::string& pathA, const std::string& pathB, double tolerance)
{
    std::map<std::string, openvdb::GridBase::Ptr> b;
    for (const openvdb::GridBase::Ptr& grid : readVdb(pathB)) b[grid->getName()] = grid;
    GridComparison result;
    for (const openvdb::GridBase::Ptr& grid : readVdb(pathA)) {
        const auto other = b.find(grid->getName());
        if (other == b.end()) {
            result.onlyInA.push_back(grid->getName());
            continue;
        }
        GridDifference d;
        d.name = grid->getName();
        d.type = grid->valueType();
        const auto floatsA = openvdb::gridConstPtrCast<openvdb::FloatGrid>(grid);
        const auto floatsB = openvdb::gridConstPtrCast<openvdb::FloatGrid>(other->second);
        const auto vectorsA = openvdb::gridConstPtrCast<openvdb::Vec3SGrid>(grid);
        const auto vectorsB = openvdb::gridConstPtrCast<openvdb::Vec3SGrid>(other->second);
        if (floatsA && floatsB) {
            compareVoxels(*floatsA, *floatsB, tolerance, d);
        } else if (vectorsA && vectorsB) {
            compareVoxels(*vectorsA, *vectorsB, tolerance, d);
        } else {
            d.comparedByHash = true;
            d.voxels = grid->activeVoxelCount();
            d.differing = gridChecksum(*grid) == gridChecksum(*other->second) ? 0 : 1;
        }
        result.grids.push_back(d);
        b.erase(other);
    }
    for (const auto& [name, grid] : b) result.onlyInB.push_back(name);
    return result;
}

} // namespace vfield
