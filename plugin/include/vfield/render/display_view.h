#pragma once
/// @file display_view.h
/// How a frame's scene-linear light becomes display values: scaled by the
/// exposure, then through a view of an OpenColorIO config's default display,
/// as Blender, Houdini and Nuke show their renders. The config is $OCIO's
/// when it is set, else vfield's own (plugin/render/ocio/config.ocio: the
/// sRGB display's Filmic, Standard and Raw views).
///
/// vfield renders in linear Rec.709: sRGB primaries, D65 white. A config of
/// $OCIO reads the frames as its scene_linear role.

#include <vfield/render/render_settings.h>

#include <OpenImageIO/color.h>

#include <memory>
#include <string>

namespace vfield {

/// The name of the renderer's working space, as EXR headers state it.
inline constexpr const char* kWorkingSpaceName = "Linear Rec.709";
/// Its primaries and white, (x, y) of red, green, blue and white, as the
/// OpenEXR chromaticities attribute holds them.
inline constexpr float kWorkingSpaceChromaticities[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};

/// The OpenColorIO config frames are shown through: $OCIO when it is set,
/// else vfield's own, installed beside the library (share/vfield/ocio/,
/// wherever the prefix) or, for a library in its build tree, the tree's.
std::string displayConfigPath();

class DisplayView {
public:
    /// Throws OptionError naming render/view when the config's display has no
    /// such view, FileError when the config cannot be read.
    explicit DisplayView(const ViewSettings& settings);

    /// Scene-linear RGB -> display-encoded RGB in [0, 1], in place: `pixels`
    /// packed R, G, B triples.
    void apply(float* rgb, std::size_t pixels) const;

    const std::string& configPath() const { return mConfigPath; }
    const std::string& display() const { return mDisplay; }
    const std::string& view() const { return mView; }

private:
    std::string mConfigPath, mDisplay, mView;
    float mScale;
    OIIO::ColorProcessorHandle mProcessor;
};

} // namespace vfield
