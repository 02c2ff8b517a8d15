#include <vfield/field/fga_file.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <tbb/parallel_for.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace vfield {

Vec3d VectorGrid::cellCenter(int i, int j, int k) const
{
    const Vec3d extent = bounds.extents();
    const int index[3] = {i, j, k};
    Vec3d p;
    for (int axis = 0; axis < 3; ++axis) p[axis] = bounds.min()[axis] + (index[axis] + 0.5) * extent[axis] / size[axis];
    return p;
}

VectorGrid sampleField(const OctreeField& field, int cells)
{
    if (cells < 1 || cells > 1024) throw ValueError("an FGA grid has 1 to 1024 cells per axis, not " + std::to_string(cells));
    VectorGrid grid;
    grid.size = {cells, cells, cells};
    grid.bounds = field.bounds();
    grid.values.resize(std::size_t(cells) * cells * cells);
    tbb::parallel_for(0, cells, [&](int k) {
        for (int j = 0; j < cells; ++j)
            for (int i = 0; i < cells; ++i)
                grid.values[std::size_t(i) + std::size_t(cells) * (std::size_t(j) + std::size_t(cells) * k)] =
                    field.sample(grid.cellCenter(i, j, k)).force;
    });
    return grid;
}

void writeFga(const std::string& path, const VectorGrid& grid)
{
    std::string text;
    text.reserve(grid.values.size() * 40 + 256);
    char line[160];
    const auto add = [&](double x, double y, double z) {
        std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,\n", x, y, z);
        text += line;
    };
    add(grid.size[0], grid.size[1], grid.size[2]);
    add(grid.bounds.min()[0], grid.bounds.min()[1], grid.bounds.min()[2]);
    add(grid.bounds.max()[0], grid.bounds.max()[1], grid.bounds.max()[2]);
    for (const Vec3f& v : grid.values) add(v[0], v[1], v[2]);
    writeTextAtomically(path, text);
}

VectorGrid readFga(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, "cannot be read");
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    std::size_t position = 0, count = 0;
    const auto next = [&]() {
        while (position < text.size() && (text[position] == ',' || std::isspace(static_cast<unsigned char>(text[position]))))
            ++position;
        if (position >= text.size()) throw FileError(path, "ends after " + std::to_string(count) + " values");
        const char* start = text.c_str() + position;
        char* end = nullptr;
        const double value = std::strtod(start, &end);
        if (end == start) throw FileError(path, "value " + std::to_string(count + 1) + " is not a number");
        position += std::size_t(end - start);
        ++count;
        return value;
    };
    VectorGrid grid;
    for (int& n : grid.size) {
        const double value = next();
        if (!(value >= 1 && value <= 1024) || value != std::floor(value))
            throw FileError(path, "grid size " + std::to_string(value) + " is not a whole number from 1 to 1024");
        n = int(value);
    }
    Vec3d lo, hi;
    for (int axis = 0; axis < 3; ++axis) lo[axis] = next();
    for (int axis = 0; axis < 3; ++axis) hi[axis] = next();
    grid.bounds = BBoxd(lo, hi);
    grid.values.resize(std::size_t(grid.size[0]) * grid.size[1] * grid.size[2]);
    for (Vec3f& v : grid.values)
        for (int axis = 0; axis < 3; ++axis) v[axis] = float(next());
    return grid;
}

} // namespace vfield
