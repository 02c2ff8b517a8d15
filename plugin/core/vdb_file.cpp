#include <vfield/core/vdb_file.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/hash.h>

#include <openvdb/io/File.h>
#include <openvdb/points/PointDataGrid.h>

#include <cstring>
#include <sstream>

namespace vfield {

void writeVdb(const std::string& path, const openvdb::GridPtrVec& grids, const openvdb::MetaMap& fileMetadata)
{
    openvdb::initialize();
    writeFileAtomically(path, [&](const std::string& temporary) {
        try {
            openvdb::io::File file(temporary);
            file.write(grids, fileMetadata);
            file.close();
        } catch (const openvdb::Exception& e) {
            throw FileError(path, std::string("cannot write: ") + e.what());
        }
    });
}

openvdb::GridPtrVec readVdb(const std::string& path, openvdb::MetaMap* fileMetadata)
{
    openvdb::initialize();
    openvdb::GridPtrVecPtr grids;
    try {
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/false);
        grids = file.getGrids();
        if (fileMetadata) *fileMetadata = *file.getMetadata();
        file.close();
    } catch (const openvdb::Exception& e) {
        throw FileError(path, std::string("cannot read OpenVDB file: ") + e.what());
    } catch (const std::exception& e) {
        throw FileError(path, std::string("cannot read OpenVDB file: ") + e.what());
    }
    if (!grids || grids->empty()) throw FileError(path, "the OpenVDB file holds no grid");
    for (const auto& grid : *grids)
        if (!grid) throw FileError(path, "the OpenVDB file holds an unreadable grid");
    return *grids;
}

openvdb::MetaMap readVdbMetadata(const std::string& path)
{
    openvdb::initialize();
    try {
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/true); // the header and metadata only: no grid is read
        openvdb::MetaMap metadata = *file.getMetadata();
        file.close();
        return metadata;
    } catch (const std::exception& e) {
        throw FileError(path, std::string("cannot read OpenVDB file: ") + e.what());
    }
}

GridSummary summarizeGrid(const openvdb::GridBase& grid)
{
    GridSummary summary;
    summary.name = grid.getName();
    summary.type = grid.valueType();
    summary.voxelSize = grid.voxelSize();
    summary.activeVoxels = grid.activeVoxelCount();
    summary.memoryBytes = grid.memUsage();
    const openvdb::CoordBBox active = grid.evalActiveVoxelBoundingBox();
    if (!active.empty()) {
        // The world box of the voxels' extents (index box grown by half a voxel).
        const openvdb::BBoxd index(active.min().asVec3d() - 0.5, active.max().asVec3d() + 0.5);
        summary.worldBounds = grid.transform().indexToWorld(index);
    }
    return summary;
}

namespace {

template<typename ValueT>
void addValue(ContentHash& hash, const ValueT& value)
{
    hash.addValue(value);
}

void addValue(ContentHash& hash, bool value)
{
    const unsigned char byte = value ? 1 : 0;
    hash.add(&byte, 1);
}

} // namespace

uint64_t gridChecksum(const openvdb::GridBase& grid)
{
    ContentHash hash;
    hash.add(grid.getName());
    hash.add(grid.type());
    const openvdb::math::Mat4d matrix = grid.transform().baseMap()->getAffineMap()->getMat4();
    hash.add(matrix.asPointer(), 16 * sizeof(double));

    if (const auto* points = dynamic_cast<const openvdb::points::PointDataGrid*>(&grid)) {
        // Points: each leaf's origin, then every attribute's name and values.
        for (auto leaf = points->tree().cbeginLeaf(); leaf; ++leaf) {
            const openvdb::Coord origin = leaf->origin();
            hash.add(&origin, sizeof origin);
            const openvdb::points::AttributeSet::Descriptor& descriptor = leaf->attributeSet().descriptor();
            for (const auto& [name, index] : descriptor.map()) {
                hash.add(name);
                std::ostringstream bytes;
                leaf->constAttributeArray(index).writeBuffers(bytes, /*outputTransient=*/false);
                hash.add(bytes.str());
            }
        }
        return hash.value();
    }
    using DenseValueGrids =
        openvdb::NumericGridTypes::Append<openvdb::Vec3GridTypes>::Append<openvdb::BoolGrid, openvdb::MaskGrid>;
    const bool known = grid.apply<DenseValueGrids>([&hash](const auto& typed) {
        addValue(hash, typed.background());
        for (auto it = typed.tree().cbeginValueOn(); it; ++it) {
            const openvdb::CoordBBox box = it.getBoundingBox();
            hash.add(&box, sizeof box);
            addValue(hash, it.getValue());
        }
    });
    if (!known) throw ValueError("cannot checksum grid '" + grid.getName() + "' of type " + grid.type());
    return hash.value();
}

} // namespace vfield
