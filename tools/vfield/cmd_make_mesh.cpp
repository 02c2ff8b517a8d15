// vfield make-mesh terrain|sphere|box -o mesh.obj: procedural meshes as files.

#include "command.h"

#include <vfield/mesh/mesh_io.h>
#include <vfield/mesh/procedural.h>

namespace vfield::cli {

namespace {

void addVec3Option(CLI::App& command, const std::string& name, Vec3d& value, const std::string& help)
{
    command
        .add_option_function<std::vector<double>>(
            name, [&value](const std::vector<double>& v) { value = Vec3d(v[0], v[1], v[2]); }, help)
        ->expected(3)
        ->delimiter(',')
        ->default_str(std::to_string(value[0]) + "," + std::to_string(value[1]) + "," + std::to_string(value[2]));
}

} // namespace

Runner registerMakeMesh(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        std::string output;
        TerrainSettings terrain;
        SphereSettings sphere;
        BoxSettings box;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("make-mesh", "Write a procedural mesh (closed, y up) to an OBJ file");
    command->require_subcommand(1);
    command->add_option("-o,--output", o->output, "Output .obj file")->required();

    CLI::App* terrain = command->add_subcommand("terrain", "Fractal heightfield closed into a solid");
    TerrainSettings& t = o->terrain;
    terrain->add_option("--seed", t.seed, "Noise seed")->capture_default_str();
    terrain->add_option("--size-x", t.sizeX, "Extent along x, world units")->capture_default_str();
    terrain->add_option("--size-z", t.sizeZ, "Extent along z, world units")->capture_default_str();
    terrain->add_option("--cells-x", t.cellsX, "Grid cells along x")->capture_default_str();
    terrain->add_option("--cells-z", t.cellsZ, "Grid cells along z")->capture_default_str();
    terrain->add_option("--amplitude", t.amplitude, "Height of the noise, world units")->capture_default_str();
    terrain->add_option("--feature-size", t.featureSize, "Wavelength of the coarsest octave, world units")->capture_default_str();
    terrain->add_option("--octaves", t.octaves, "Noise octaves")->capture_default_str();
    terrain->add_option("--roughness", t.roughness, "Amplitude ratio of successive octaves")->capture_default_str();
    terrain->add_option("--base-thickness", t.baseThickness, "Depth of the solid below the lowest point")->capture_default_str();

    CLI::App* sphere = command->add_subcommand("sphere", "Icosphere");
    addVec3Option(*sphere, "--center", o->sphere.center, "Centre x,y,z, world units");
    sphere->add_option("--radius", o->sphere.radius, "Radius, world units")->capture_default_str();
    sphere->add_option("--subdivisions", o->sphere.subdivisions, "Icosahedron subdivisions (20 * 4^n triangles)")
        ->capture_default_str();

    CLI::App* box = command->add_subcommand("box", "Axis-aligned box");
    addVec3Option(*box, "--min", o->box.min, "Minimum corner x,y,z, world units");
    addVec3Option(*box, "--max", o->box.max, "Maximum corner x,y,z, world units");

    return [o, terrain, sphere, &global] {
        TriangleMesh mesh;
        if (terrain->parsed()) mesh = makeTerrain(o->terrain);
        else if (sphere->parsed()) mesh = makeSphere(o->sphere);
        else mesh = makeBox(o->box);
        saveObj(mesh, o->output);
        log(global, o->output + ": " + std::to_string(mesh.triangleCount()) + " triangles");
    };
}

} // namespace vfield::cli
