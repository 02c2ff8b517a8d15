/* A host written in C that loads libvfield at run time, as a plugin host does:
 * dlopen, dlsym and the C API of vfield.h (the installed header). It simulates
 * cloud_on_box.json, a cloud of 2000 particles falling on a box, to frame 12
 * and checks what the frame holds. Prints "ok" and exits 0, or names the
 * first check that fails and exits 1.
 * Usage: dlopen_host LIBVFIELD.so SCENE.json */
#include <vfield/vfield.h>

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

/* Exits when a symbol is missing: a host cannot go on without it. */
static void* symbol(void* library, const char* name)
{
    void* address = dlsym(library, name);
    if (!address) {
        fprintf(stderr, "dlopen host: no %s in the library\n", name);
        _Exit(1);
    }
    return address;
}

static int check(int holds, const char* what)
{
    if (!holds) fprintf(stderr, "dlopen host: %s does not hold\n", what);
    return holds;
}

int main(int argc, char** argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: dlopen_host LIBVFIELD.so SCENE.json\n");
        return 2;
    }
    void* library = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        fprintf(stderr, "dlopen host: %s\n", dlerror());
        return 1;
    }
    /* A function pointer from dlsym's void*, the POSIX way. */
    int (*api_version)(void);
    vfield_session* (*open_session)(const char*, char*, size_t);
    int (*step_to)(vfield_session*, int, char*, size_t);
    size_t (*particle_count)(const vfield_session*);
    const float* (*particle_positions)(const vfield_session*);
    double (*density_sample)(vfield_session*, double, double, double);
    uint64_t (*active_voxels)(vfield_session*);
    void (*close_session)(vfield_session*);
    *(void**)&api_version = symbol(library, "vfield_api_version");
    *(void**)&open_session = symbol(library, "vfield_open");
    *(void**)&step_to = symbol(library, "vfield_step_to");
    *(void**)&particle_count = symbol(library, "vfield_particle_count");
    *(void**)&particle_positions = symbol(library, "vfield_particle_positions");
    *(void**)&density_sample = symbol(library, "vfield_density_sample");
    *(void**)&active_voxels = symbol(library, "vfield_density_active_voxels");
    *(void**)&close_session = symbol(library, "vfield_close");

    if (!check(api_version() == VFIELD_C_API_VERSION, "the library's C API version is the header's")) return 1;
    char error[256] = "";
    vfield_session* session = open_session(argv[2], error, sizeof error);
    if (!session) {
        fprintf(stderr, "dlopen host: %s\n", error);
        return 1;
    }
    if (step_to(session, 12, error, sizeof error) != 0) {
        fprintf(stderr, "dlopen host: %s\n", error);
        return 1;
    }
    /* The cloud keeps its particles, and its density is where they are and
     * nowhere far above them. */
    const float* p = particle_positions(session);
    const int ok = check(particle_count(session) == 2000, "2000 particles at frame 12") &&
                   check(density_sample(session, p[0], p[1], p[2]) > 0.0, "density at the first particle") &&
                   check(density_sample(session, 0.0, 100.0, 0.0) == 0.0, "no density 100 units up") &&
                   check(active_voxels(session) > 0, "active density voxels");
    if (ok) printf("ok: 2000 particles at frame 12, %llu active density voxels\n", (unsigned long long)active_voxels(session));
    close_session(session);
    dlclose(library);
    return ok ? 0 : 1;
}
