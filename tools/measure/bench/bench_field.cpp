// Benchmarks of the field stage: octree build, point queries, voxelization.

#include <vfield/field/field_grid.h>
#include <vfield/field/octree_field.h>
#include <vfield/mesh/procedural.h>

#include <benchmark/benchmark.h>

#include <map>
#include <random>

using namespace vfield;

namespace {

/// The showcase-like terrain with about `triangles` surface triangles, built once.
const TriangleMesh& terrainWithTriangles(int64_t triangles)
{
    static std::map<int64_t, TriangleMesh> cache;
    auto it = cache.find(triangles);
    if (it == cache.end()) {
        TerrainSettings options;
        options.cellsX = options.cellsZ = int(std::sqrt(double(triangles) / 2.0));
        it = cache.emplace(triangles, makeTerrain(options)).first;
    }
    return it->second;
}

const OctreeField& terrainField(int64_t triangles)
{
    static std::map<int64_t, OctreeField> cache;
    auto it = cache.find(triangles);
    if (it == cache.end()) it = cache.emplace(triangles, OctreeField::build(terrainWithTriangles(triangles))).first;
    return it->second;
}

void BM_OctreeBuild(benchmark::State& state)
{
    const TriangleMesh& mesh = terrainWithTriangles(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(OctreeField::build(mesh));
    state.SetItemsProcessed(state.iterations() * int64_t(mesh.triangleCount()));
    state.counters["triangles"] = double(mesh.triangleCount());
}
BENCHMARK(BM_OctreeBuild)
    ->Arg(100'000)
    ->Arg(200'000)
    ->Arg(400'000)
    ->Arg(800'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_PointQueries(benchmark::State& state)
{
    const OctreeField& field = terrainField(1'000'000);
    // Uniform points in the root, a different stream per thread.
    std::mt19937_64 random(uint64_t(state.thread_index()) + 1);
    std::vector<Vec3d> points(1 << 16);
    const BBoxd& root = field.bounds();
    for (Vec3d& p : points)
        for (int axis = 0; axis < 3; ++axis)
            p[axis] = root.min()[axis] + root.extents()[axis] * (double(random() >> 11) / double(1ull << 53));
    for (auto _ : state)
        for (const Vec3d& p : points) benchmark::DoNotOptimize(field.sample(p));
    state.SetItemsProcessed(state.iterations() * int64_t(points.size()));
}
BENCHMARK(BM_PointQueries)->Threads(1)->Threads(2)->UseRealTime();

void BM_Voxelize(benchmark::State& state)
{
    const OctreeField& field = terrainField(state.range(0));
    std::size_t bytes = 0, activeVoxels = 0;
    for (auto _ : state) {
        const FieldGrids grids = voxelizeField(field);
        bytes = grids.force->memUsage() + grids.level->memUsage() + grids.surface->memUsage();
        activeVoxels = grids.force->activeVoxelCount();
    }
    state.counters["grid_MiB"] = double(bytes) / 1048576.0;
    state.counters["dense_MiB"] = double(activeVoxels) * sizeof(openvdb::Vec3s) / 1048576.0;
    state.counters["leaves"] = double(field.leafCount());
}
BENCHMARK(BM_Voxelize)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
