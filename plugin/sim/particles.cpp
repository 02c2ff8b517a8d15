#include <vfield/sim/particles.h>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

namespace vfield {

void ParticleSet::reserve(std::size_t n)
{
    position.reserve(n);
    velocity.reserve(n);
    rest.reserve(n);
    peak.reserve(n);
    origin.reserve(n);
    id.reserve(n);
    radius.reserve(n);
    cloud.reserve(n);
}

void ParticleSet::keep(const std::vector<uint8_t>& alive)
{
    keepFlagged(position, alive);
    keepFlagged(velocity, alive);
    keepFlagged(rest, alive);
    keepFlagged(rest2, alive);
    keepFlagged(peak, alive);
    keepFlagged(origin, alive);
    keepFlagged(birth, alive);
    keepFlagged(death, alive);
    keepFlagged(fade, alive);
    keepFlagged(id, alive);
    keepFlagged(radius, alive);
    keepFlagged(cloud, alive);
}

namespace {

/// The low 10 bits of v spread to every third bit.
uint32_t spreadBits(uint32_t v)
{
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x30000ffu;
    v = (v | (v << 8)) & 0x300f00fu;
    v = (v | (v << 4)) & 0x30c30c3u;
    v = (v | (v << 2)) & 0x9249249u;
    return v;
}

template<typename T>
void permute(std::vector<T>& values, const std::vector<uint32_t>& order)
{
    if (values.empty()) return; // an optional attribute (rest2, peak, birth, ...) not kept
    std::vector<T> sorted(values.size());
    for (std::size_t i = 0; i < order.size(); ++i) sorted[i] = values[order[i]];
    values = std::move(sorted);
}

} // namespace

void ParticleSet::sortSpatially(const BBoxd& box)
{
    constexpr double kCells = 1024.0;
    const Vec3d extent = box.extents();
    std::vector<std::pair<uint32_t, uint32_t>> order(size());
    tbb::parallel_for(std::size_t(0), size(), [&](std::size_t p) {
        uint32_t cell[3];
        for (int axis = 0; axis < 3; ++axis) {
            const double u = extent[axis] > 0.0 ? (double(position[p][axis]) - box.min()[axis]) / extent[axis] : 0.0;
            cell[axis] = uint32_t(std::clamp(u * kCells, 0.0, kCells - 1.0));
        }
        order[p] = {spreadBits(cell[0]) | (spreadBits(cell[1]) << 1) | (spreadBits(cell[2]) << 2), uint32_t(p)};
    });
    tbb::parallel_sort(order.begin(), order.end()); // (key, index) pairs are distinct: one order for any thread count
    std::vector<uint32_t> indices(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) indices[i] = order[i].second;
    reorder(indices);
}

void ParticleSet::sortById()
{
    std::vector<uint32_t> order(size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return id[a] < id[b]; });
    reorder(order);
}

void ParticleSet::append(const ParticleSet& other)
{
    const auto add = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
    add(position, other.position);
    add(velocity, other.velocity);
    add(rest, other.rest);
    add(rest2, other.rest2);
    add(peak, other.peak);
    add(origin, other.origin);
    add(birth, other.birth);
    add(death, other.death);
    add(fade, other.fade);
    add(id, other.id);
    add(radius, other.radius);
    add(cloud, other.cloud);
}

void ParticleSet::reorder(const std::vector<uint32_t>& order)
{
    permute(position, order);
    permute(velocity, order);
    permute(rest, order);
    permute(rest2, order);
    permute(peak, order);
    permute(origin, order);
    permute(birth, order);
    permute(death, order);
    permute(fade, order);
    permute(id, order);
    permute(radius, order);
    permute(cloud, order);
}

} // namespace vfield
