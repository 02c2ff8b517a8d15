#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/host/session.h>
#include <vfield/vfield.h>

#include <catch2/catch.hpp>

#include <dlfcn.h>
#include <fstream>

namespace {

const char* kScene = R"({"version": 1, "frames": {"start": 1, "end": 20, "fps": 24}, "seed": 3,
  "objects": [{"name": "ground", "mesh": {"box": {"min": [-20, -2, -20], "max": [20, 0, 20]}},
               "repulsion": {"strength": 2, "maxLevel": 6}}],
  "clouds": [{"count": 2000, "center": [0, 6, 0], "radius": 3, "particleRadius": 0.5}],
  "fields": [{"acceleration": [0, -9.81, 0]}],
  "volume": {"voxelSize": 0.5}})";

template<typename F>
F symbol(void* library, const char* name)
{
    void* address = dlsym(library, name);
    INFO(name);
    REQUIRE(address != nullptr);
    return reinterpret_cast<F>(address);
}

} // namespace

TEST_CASE("plugin: a host loads libvfield at run time and reads a frame's density", "[plugin]")
{
    const std::string dir = vfield::test::scratchDir("plugin");
    std::ofstream(dir + "/scene.json") << kScene;

    void* library = dlopen(VFIELD_LIBRARY_PATH, RTLD_NOW | RTLD_LOCAL);
    INFO(dlerror());
    REQUIRE(library != nullptr);
    const auto version = symbol<int (*)()>(library, "vfield_api_version");
    const auto open = symbol<vfield_session* (*)(const char*, char*, size_t)>(library, "vfield_open");
    const auto stepTo = symbol<int (*)(vfield_session*, int, char*, size_t)>(library, "vfield_step_to");
    const auto count = symbol<size_t (*)(const vfield_session*)>(library, "vfield_particle_count");
    const auto checksum = symbol<uint64_t (*)(vfield_session*)>(library, "vfield_density_checksum");
    const auto sample = symbol<double (*)(vfield_session*, double, double, double)>(library, "vfield_density_sample");
    const auto close = symbol<void (*)(vfield_session*)>(library, "vfield_close");
    REQUIRE(version() == VFIELD_C_API_VERSION);

    char error[256] = "";
    CHECK(open((dir + "/missing.json").c_str(), error, sizeof error) == nullptr);
    CHECK(std::string(error) == dir + "/missing.json: no such file");

    vfield_session* session = open((dir + "/scene.json").c_str(), error, sizeof error);
    INFO(error);
    REQUIRE(session != nullptr);
    REQUIRE(stepTo(session, 12, error, sizeof error) == 0);
    CHECK(count(session) == 2000);
    CHECK(stepTo(session, 5, error, sizeof error) == -1); // backwards is refused
    CHECK(std::string(error).find("forwards only") != std::string::npos);

    // The same frame through the C++ API in this process gives the same grid.
    vfield::Session direct(dir + "/scene.json");
    direct.stepTo(12);
    CHECK(checksum(session) == vfield::gridChecksum(*direct.volume().density));
    // The cloud's density is where its particles are.
    const vfield::Vec3f p = direct.particles().position[0];
    CHECK(sample(session, p[0], p[1], p[2]) > 0.0);
    CHECK(sample(session, 0.0, 100.0, 0.0) == 0.0);
    close(session);
    dlclose(library);
}
