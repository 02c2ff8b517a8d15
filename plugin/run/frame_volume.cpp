#include <vfield/run/frame_volume.h>

#include <vfield/core/stopwatch.h>
#include <vfield/volume/particle_grid.h>

#include <tbb/parallel_invoke.h>

#include <algorithm>

namespace vfield {

FrameFiles writeFrameVolume(const SimFolder& folder, int frame, const ParticleSet& particles, const VolumeSettings& volume,
                            uint64_t inputsHash, StageSeconds& stages)
{
    const Stopwatch watch;
    SplatSeconds splat;
    FrameFiles files;
    tbb::parallel_invoke(
        [&] { files.density = folder.writeDensity(frame, splatParticles(particles, volume, &splat), inputsHash); },
        [&] {
            files.particles = folder.writeParticles(frame, makeParticleGrid(particles, volume.particlePrecision), inputsHash);
        });
    stages.splat += splat.splat;
    stages.detail += splat.detail;
    stages.write += std::max(0.0, watch.seconds() - splat.splat - splat.detail);
    return files;
}

} // namespace vfield
