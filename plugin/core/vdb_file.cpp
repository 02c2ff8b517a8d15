#include <vfield/core/vdb_file.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <openvdb/io/File.h>
#include <openvdb/points/PointDataGrid.h>

#include <cstring>
#include <sstream>

namespace vfield {

void writeVdb(const std::string& path, const openvdb::GridPtrVec& grids)
{
    openvdb::initialize();
    writeFileAtomically(path, [&](const std::string& temporary) {
        try {
            openvdb::io::File file(temporary);
            file.write(grids);
            file.close();
        } catch (const openvdb::Exception& e) {
            throw FileError(path, std::string("cannot write: ") + e.what());
        }
    });
}

openvdb::GridPtrVec readVdb(const std::string& path)
{
    openvdb::initialize();
    openvdb::GridPtrVecPtr grids;
    try {
        openvdb::io::File file(path);
        file.open(/*delayLoad=*/false);
        grids = file.getGrids();
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

/// Mixes 8-byte words (SplitMix64 finalizer); order-dependent and fast.
class ContentHash {
public:
    void add(const void* data, std::size_t size)
    {
        const auto* bytes = static_cast<const unsigned char*>(data);
        while (size > 0) {
            uint64_t word = 0;
            const std::size_t n = std::min<std::size_t>(size, 8);
            std::memcpy(&word, bytes, n);
            mix(word ^ (uint64_t(n) << 56));
            bytes += n;
            size -= n;
        }
    }
    void add(const std::string& text) { add(text.data(), text.size()); }
    uint64_t value() const { return mState; }

private:
    void mix(uint64_t word)
    {
        uint64_t z = (mState ^ word) + 0x9e3779b97f4a7c15ull;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        mState = z ^ (z >> 31);
    }
    uint64_t mState = 0x243f6a8885a308d3ull;
};

template<typename ValueT>
void addValue(ContentHash& hash, const ValueT& value)
{
    hash.add(&value, sizeof value);
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
