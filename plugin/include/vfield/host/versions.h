#pragma once
/// @file versions.h
/// vfield's version and those of the libraries and programs it runs with, for
/// `vfield --version` and for bug reports: the libraries' as they report
/// themselves at run time where they can (Embree, OpenImageIO), OpenVDB's as
/// its headers name the library vfield was built against, POV-Ray's as the
/// povray program the renderer would run prints it; and the OpenColorIO
/// config frames are shown through.

#include <optional>
#include <string>

namespace vfield {

struct Versions {
    std::string vfield;                ///< project(VERSION) of vfield's CMakeLists.txt: "0.1.0"
    std::string openvdb;               ///< "10.0.1"
    std::string embree;                ///< "3.13.5"
    std::string openImageIO;           ///< "2.4.7"
    std::optional<std::string> povray; ///< "3.7.0.10.unofficial"; nothing when no povray is on PATH
    std::string colourConfig;          ///< its path (vfield/render/display_view.h)
};

/// Asks each library and runs `povray --version`. Throws Error when Embree
/// cannot create a device.
Versions versions();

/// One line per component, "vfield 0.1.0", "OpenVDB 10.0.1", ..., "POV-Ray not
/// found" when there is none, "OpenColorIO config PATH"; no final newline.
std::string versionReport(const Versions& versions);

} // namespace vfield
