#include <vfield/host/versions.h>

#include <vfield/render/display_view.h>
#include <vfield/render/embree/embree_backend.h>
#include <vfield/render/povray/povray_runner.h>

#include <OpenImageIO/imageio.h>
#include <openvdb/version.h>

namespace vfield {

Versions versions()
{
    Versions v;
    v.vfield = VFIELD_VERSION;
    v.openvdb = OPENVDB_LIBRARY_VERSION_STRING;
    v.embree = embreeVersion();
    // OpenImageIO packs its version as major * 10000 + minor * 100 + patch.
    const int oiio = OIIO::openimageio_version();
    v.openImageIO = std::to_string(oiio / 10000) + "." + std::to_string(oiio / 100 % 100) + "." + std::to_string(oiio % 100);
    v.povray = povrayVersion();
    v.colourConfig = displayConfigPath();
    return v;
}

std::string versionReport(const Versions& versions)
{
    return "vfield " + versions.vfield + "\nOpenVDB " + versions.openvdb + "\nEmbree " + versions.embree + "\nOpenImageIO " +
           versions.openImageIO + "\nPOV-Ray " + versions.povray.value_or("not found") + "\nOpenColorIO config " +
           versions.colourConfig;
}

} // namespace vfield
