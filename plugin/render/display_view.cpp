#include <vfield/render/display_view.h>

#include <vfield/core/error.h>

#include <tbb/parallel_for.h>

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

namespace vfield {

std::string displayConfigPath()
{
    if (const char* ocio = std::getenv("OCIO"); ocio && *ocio) return ocio;
    // Installed, the config lies where it was installed relative to this
    // library, wherever the prefix; a library in its build tree uses the tree's.
    Dl_info library;
    if (dladdr(reinterpret_cast<void*>(&displayConfigPath), &library) && library.dli_fname) {
        const std::filesystem::path installed =
            std::filesystem::path(library.dli_fname).parent_path() / VFIELD_OCIO_CONFIG_FROM_LIBRARY;
        if (std::filesystem::exists(installed)) return installed.lexically_normal().string();
    }
    return VFIELD_BUILD_OCIO_CONFIG;
}

namespace {

/// OpenColorIO's message on one line, as vfield's errors are.
std::string errorOf(OIIO::ColorConfig& config)
{
    std::string why = config.geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    return why;
}

} // namespace

DisplayView::DisplayView(const ViewSettings& settings)
    : mConfigPath(displayConfigPath()), mView(settings.view), mScale(float(std::exp2(settings.exposure)))
{
    settings.validate();
    if (!OIIO::ColorConfig::supportsOpenColorIO())
        throw Error("this OpenImageIO was built without OpenColorIO: frames cannot be shown through a view");
    OIIO::ColorConfig config(mConfigPath);
    if (config.has_error()) throw FileError(mConfigPath, "cannot read the OpenColorIO config: " + errorOf(config));
    const char* display = config.getDefaultDisplayName();
    const char* sceneLinear = config.getColorSpaceNameByRole("scene_linear");
    if (!display || !sceneLinear) throw FileError(mConfigPath, "the OpenColorIO config needs a display and a scene_linear role");
    mDisplay = display;
    std::string views;
    bool known = false;
    for (int i = 0; i < config.getNumViews(mDisplay); ++i) {
        const std::string name = config.getViewNameByIndex(mDisplay, i);
        views += (views.empty() ? "" : ", ") + name;
        known = known || name == mView;
    }
    if (!known)
        throw OptionError("render/view", "expected a view of display '" + mDisplay + "' in " + mConfigPath + " (" + views +
                                             "), got '" + mView + "'");
    mProcessor = config.createDisplayTransform(mDisplay, mView, sceneLinear);
    if (!mProcessor) throw FileError(mConfigPath, "cannot make the view '" + mView + "': " + errorOf(config));
}

void DisplayView::apply(float* rgb, std::size_t pixels) const
{
    constexpr std::size_t kChunk = 4096; // pixels a task converts
    tbb::parallel_for(std::size_t(0), (pixels + kChunk - 1) / kChunk, [&](std::size_t chunk) {
        float* first = rgb + 3 * chunk * kChunk;
        const std::size_t count = std::min(kChunk, pixels - chunk * kChunk);
        if (mScale != 1.0f)
            for (std::size_t i = 0; i < 3 * count; ++i) first[i] *= mScale;
        mProcessor->apply(first, int(count), 1, 3, sizeof(float), 3 * sizeof(float), 3 * count * sizeof(float));
    });
}

} // namespace vfield
