// The C entry point (vfield.h): a thin shell over vfield::Session that turns
// exceptions into return codes and messages, so none crosses the C boundary.

#include <vfield/vfield.h>

#include <vfield/core/vdb_file.h>
#include <vfield/host/session.h>

#include <openvdb/tools/Interpolation.h>

#include <cstring>

struct vfield_session {
    vfield::Session session;
};

namespace {

void report(const char* message, char* error, size_t size)
{
    if (!error || size == 0) return;
    std::strncpy(error, message, size - 1);
    error[size - 1] = '\0';
}

template<typename F>
int guarded(char* error, size_t size, F&& body)
{
    try {
        body();
        return 0;
    } catch (const std::exception& e) {
        report(e.what(), error, size);
    } catch (...) {
        report("unknown error", error, size);
    }
    return -1;
}

} // namespace

extern "C" {

int vfield_api_version(void) { return VFIELD_C_API_VERSION; }

vfield_session* vfield_open(const char* scene_path, char* error, size_t error_size)
{
    vfield_session* session = nullptr;
    if (!scene_path) {
        report("no scene path given", error, error_size);
        return nullptr;
    }
    guarded(error, error_size, [&] { session = new vfield_session{vfield::Session(scene_path)}; });
    return session;
}

void vfield_close(vfield_session* session) { delete session; }

int vfield_step_to(vfield_session* session, int frame, char* error, size_t error_size)
{
    if (!session) {
        report("no session", error, error_size);
        return -1;
    }
    return guarded(error, error_size, [&] { session->session.stepTo(frame); });
}

int vfield_frame(const vfield_session* s) { return s ? s->session.frame() : -1; }
int vfield_first_frame(const vfield_session* s) { return s ? s->session.scene().simulation.firstFrame : -1; }
int vfield_last_frame(const vfield_session* s) { return s ? s->session.scene().simulation.lastFrame : -1; }

size_t vfield_particle_count(const vfield_session* s) { return s ? s->session.particles().size() : 0; }

const float* vfield_particle_positions(const vfield_session* s)
{
    if (!s || s->session.particles().size() == 0) return nullptr;
    static_assert(sizeof(vfield::Vec3f) == 3 * sizeof(float), "positions are packed xyz floats");
    return s->session.particles().position.front().asPointer();
}

double vfield_density_sample(vfield_session* s, double x, double y, double z)
{
    if (!s) return 0.0;
    try {
        const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*s->session.volume().density);
        return sampler.wsSample(openvdb::Vec3d(x, y, z));
    } catch (...) {
        return 0.0;
    }
}

uint64_t vfield_density_active_voxels(vfield_session* s)
{
    try {
        return s ? s->session.volume().density->activeVoxelCount() : 0;
    } catch (...) {
        return 0;
    }
}

uint64_t vfield_density_checksum(vfield_session* s)
{
    try {
        return s ? vfield::gridChecksum(*s->session.volume().density) : 0;
    } catch (...) {
        return 0;
    }
}

int vfield_density_write(vfield_session* s, const char* path, char* error, size_t error_size)
{
    if (!s || !path) {
        report("no session or path", error, error_size);
        return -1;
    }
    return guarded(error, error_size, [&] {
        const vfield::DensityGrids& volume = s->session.volume();
        vfield::writeVdb(path, {volume.density, volume.velocity});
    });
}

} // extern "C"
