#pragma once
/// @file frame_image.h
/// A rendered frame (RenderImage, what a back-end produces) -> image files
/// through OpenImageIO, atomically: .png: 8-bit colour through the display
/// view (the sky included); .exr: scene-linear R, G, B, A and Z (camera
/// distance, +inf for sky), and the render passes as layers named as Nuke's
/// and Blender's multilayer EXRs name them (layer.channel), its header naming
/// the working space and the objects' indices.

#include <vfield/render/display_view.h>

#include <OpenImageIO/imagebuf.h>

#include <string>
#include <vector>

namespace vfield {

/// The layers a compositor takes a frame apart by, per pixel, rows top-down.
/// The beauty is the cloud over the surfaces: rgba = cloud + surfaces x (1 -
/// cloud alpha), exactly, in every pixel.
struct RenderPasses {
    /// RGBA, premultiplied: the light the cloud sends to the camera, and its
    /// coverage (1 - its transmittance).
    std::vector<float> cloud;
    /// RGBA, premultiplied: what lies behind the cloud (surfaces, a drawn sky)
    /// as the camera would see it without the cloud; within a pixel, its
    /// samples weighted by the cloud's transmittance, so that the cloud over
    /// it is the beauty.
    std::vector<float> surfaces;
    /// The share of the sun's light the cloud takes from the surfaces seen (0:
    /// none; 0 where the sun does not reach them anyway).
    std::vector<float> shadow;
    /// XYZ: the surfaces' shading normals, world space, averaged over the
    /// pixel's samples (0 where the sky is seen).
    std::vector<float> normal;
    /// The nearest surface's object index + 1 (scene order); 0 where none is seen.
    std::vector<float> objectIndex;
    /// XYZW: the screen motion of what lies behind the cloud (ScreenMotion),
    /// averaged over the pixel's samples; 0 when the frame was not given one.
    std::vector<float> vector;
    /// The scene's objects' names, by index, for the EXR header.
    std::vector<std::string> objectNames;

    bool empty() const { return cloud.empty(); }
};

struct RenderImage {
    int width = 0, height = 0;
    /// Linear RGB premultiplied by A: A is 1 where surfaces or a drawn sky
    /// are seen; with a transparent sky, the coverage by surfaces and cloud
    /// (0 for clear sky, 1 - transmittance through cloud).
    std::vector<float> rgba;
    std::vector<float> depth; ///< camera distance to the first surface; +inf for sky
    RenderPasses passes;      ///< empty unless the renderer was asked for them
};

/// A linear value clamped to [0, 1] and sRGB-encoded: how far apart two
/// samples look, whatever the view.
float linearToSrgb(float v);

/// The display image: RGB through the view, floats.
OIIO::ImageBuf toDisplay(const RenderImage& image, const DisplayView& view);
/// The display image of a scene-linear image's first three channels.
OIIO::ImageBuf toDisplay(const OIIO::ImageBuf& linear, const DisplayView& view);
/// The linear image: RGBAZ, then the passes' layers when the image has them.
OIIO::ImageBuf toLinear(const RenderImage& image);

/// Writes by extension (.png through the view, or .exr, its colours at the
/// depth given). Throws FileError.
void writeFrameImage(const RenderImage& image, const std::string& path, const DisplayView& view,
                     ExrDepth exrDepth = ExrDepth::Half);

/// Writes the two image files next to each other (left, then right, tops
/// aligned) into one image at path. Throws FileError.
void writeSideBySide(const std::string& left, const std::string& right, const std::string& path);

} // namespace vfield
