#pragma once
/// @file povray_settings.h
/// The POV-Ray back-end's own settings, a scene's "povray" object: what it
/// reads beside the render settings every back-end reads.

#include <vfield/core/fields.h>

namespace vfield {

/// How the POV-Ray back-end trades time for quality.
enum class PovrayQuality {
    /// Every pixel supersampled on an unjittered n x n grid (samplesPerPixel =
    /// n^2), media sampled at every volumeStep: what the golden images take.
    Final,
    /// Antialiasing where a pixel differs from its neighbours by more than
    /// 0.3 only (2 x 2, one level deep), a quarter of the media samples
    /// (at least 8): for previews and farm dailies.
    Preview
};
inline constexpr EnumName<PovrayQuality> kPovrayQualityNames[] = {{PovrayQuality::Final, "final"},
                                                                  {PovrayQuality::Preview, "preview"}};
constexpr const auto& enumNames(PovrayQuality) { return kPovrayQualityNames; }

struct PovraySettings {
    PovrayQuality quality = PovrayQuality::Final;
    int threads = 0;
    bool keepScene = false;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("quality", self.quality)
                  .doc("final supersamples every pixel (n x n for samplesPerPixel n^2) and samples the media at every "
                       "volumeStep; preview antialiases only pixels that differ from their neighbours by more than 0.3 "
                       "(2 x 2) and takes a quarter of the media samples (at least 8), for dailies"));
        visit(field("threads", self.threads)
                  .range(0, 4096)
                  .doc("POV-Ray's render threads; 1 makes its media noise reproducible; 0: as many as vfield's"));
        visit(field("keepScene", self.keepScene)
                  .doc("keep the .pov, .inc and .df3 files POV-Ray renders in OUT/povray-scene/ (a failed frame's are "
                       "always kept)"));
    }
};

} // namespace vfield
