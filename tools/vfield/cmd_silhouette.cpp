// vfield silhouette WITH WITHOUT: the box-counting dimension of a cloud's
// outline, from a frame and the same frame rendered without the cloud
// (--set /render/extinction=0); vfield silhouette --opacity FRAME.exr: from
// the frame's alpha, the cloud's opacity against a transparent sky.

#include "command.h"

#include <vfield/image/silhouette.h>

#include <cstdio>

namespace vfield::cli {

Runner registerSilhouette(CLI::App& app, const GlobalOptions&)
{
    struct Options {
        std::string withCloud, withoutCloud;
        bool opacity = false;
        SilhouetteOptions measure;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand(
        "silhouette", "The box-counting dimension of a cloud's outline: a frame against the same frame rendered without "
                      "the cloud (--set /render/extinction=0), or (--opacity) the cloud's opacity in a frame's alpha; real "
                      "clouds measure 1.33 to 1.35, a disk 1");
    command->add_option("with", o->withCloud, "The frame with the cloud")->required();
    CLI::Option* without = command->add_option("without", o->withoutCloud, "The same frame without it");
    command
        ->add_flag("--opacity", o->opacity,
                   "Measure the pixels WITH's alpha shows covered instead: the cloud's opacity, whatever its light (an EXR "
                   "rendered with --set /render/transparentSky=true, nothing but cloud in view)")
        ->excludes(without);
    command->parse_complete_callback([o] {
        if (!o->opacity && o->withoutCloud.empty())
            throw CLI::ValidationError("without", "give the frame without the cloud, or --opacity");
    });
    command
        ->add_option("--threshold", o->measure.threshold,
                     "A pixel is cloud where a channel is brighter by more, or with --opacity its alpha (0..1)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    command->add_option("--smallest-box", o->measure.smallestBox, "Smallest box, pixels (a power of two)")->capture_default_str();
    command->add_option("--largest-box", o->measure.largestBox, "Largest box, pixels (a power of two)")->capture_default_str();

    return [o] {
        const SilhouetteMeasure m = o->opacity ? measureOpacitySilhouette(o->withCloud, o->measure)
                                               : measureSilhouette(o->withCloud, o->withoutCloud, o->measure);
        std::printf("dimension %.3f, cloud %.2f%% of the pixels, outline %lld pixels; boxes", m.dimension, 100.0 * m.coverage,
                    m.boundaryPixels);
        for (const auto& [size, count] : m.boxCounts) std::printf(" %d:%lld", size, count);
        std::printf("\n");
    };
}

} // namespace vfield::cli
