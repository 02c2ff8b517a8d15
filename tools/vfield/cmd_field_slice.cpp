// vfield field-slice MESH --axis z --at 0 -o slice.png: a picture of the field.

#include "field_cli_options.h"

#include <vfield/core/image_file.h>
#include <vfield/field/field_slice.h>

namespace vfield::cli {

Runner registerFieldSlice(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        FieldCliOptions field;
        std::string output;
        FieldSliceOptions slice;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "field-slice", "Draw one slice of a mesh's octree field: cells by magnitude, force arrows, the mesh's cut");
    addFieldOptions(*command, o->field);
    command->add_option("--axis", o->slice.axis, "Normal of the slice plane")
        ->transform(CLI::CheckedTransformer(std::map<std::string, int>{{"x", 0}, {"y", 1}, {"z", 2}}))
        ->default_str("z");
    command->add_option("--at", o->slice.at, "Position of the plane along the axis, object units")->capture_default_str();
    command
        ->add_option("--sampling", o->slice.sampling,
                     "nearest: each leaf's own force (the paper's field); dual: the continuous field particles read")
        ->transform(CLI::CheckedTransformer(
            std::map<std::string, FieldSampling>{{"nearest", FieldSampling::Nearest}, {"dual", FieldSampling::Dual}}))
        ->default_str("nearest");
    command->add_option("--size", o->slice.size, "Picture edge in pixels [default: finest cells 12 pixels wide]");
    command->add_option("-o,--output", o->output, "Output image (.png, .exr, ...)")->required();

    return [o, &global] {
        const MeshAndField built = loadMeshAndBuildField(o->field, global);
        writeImage(drawFieldSlice(built.field, built.mesh, o->slice), o->output);
        log(global, o->output + ": written");
    };
}

} // namespace vfield::cli
