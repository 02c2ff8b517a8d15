#pragma once
/// @file embree_backend.h
/// vfield's own renderer as a RenderBackend: surfaces through Embree (a
/// SurfaceScene the run builds once and places its dynamic objects in each
/// frame), the cloud through OpenVDB, with the settings' integrator (fast or
/// reference). Writes OUT/frame.####.png and/or .exr (frame_image.h).

#include <vfield/render/display_view.h>
#include <vfield/render/embree/renderer.h>
#include <vfield/render/embree/scattered_light.h>
#include <vfield/render/embree/surfaces.h>
#include <vfield/render/materials.h>
#include <vfield/render/render_backend.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace vfield {

class EmbreeBackend : public RenderBackend {
public:
    /// settings and surfaces must outlive the back-end; the caller places
    /// the dynamic objects in surfaces (and commits) before each frame.
    /// formats: "png" and/or "exr". terrainLow/High: heights the terrain's
    /// colours span. objectNames: the scene's objects', by index, which EXR
    /// frames' object index pass names. Throws ValueError for an unknown
    /// format, OptionError for a view the display has not.
    EmbreeBackend(const RenderSettings& settings, const SurfaceScene& surfaces, std::map<int, SurfaceMaterial> materials,
                  double terrainLow, double terrainHigh, std::vector<std::string> formats, std::vector<std::string> objectNames);

    std::string name() const override { return "embree"; }
    std::vector<std::string> cannotDraw(const RenderSettings&) const override { return {}; }
    std::vector<std::string> frameFiles(const std::string& out, int frame) const override;
    void prepare() override {}
    void render(const FrameView& frame, const std::string& out) override;
    /// The fast integrator's paths gathered over frames: MultipleScatteringSettings::pathFramesAround.
    int framesAround() const override;
    /// Traces the frame's paths for the lattices of the frames around it.
    void look(const FrameView& frame) override;

private:
    /// The frame as the renderer takes it, its cloud `volume`.
    FrameToRender frameToRender(const FrameView& view, const CloudVolume& volume) const;

    const RenderSettings& mSettings;
    const SurfaceScene& mSurfaces;
    std::map<int, SurfaceMaterial> mMaterials;
    double mTerrainLow, mTerrainHigh;
    std::vector<std::string> mFormats;
    std::vector<std::string> mObjectNames;
    DisplayView mView;
    /// The paths of the frames looked at or rendered that later frames still read, by frame.
    std::map<int, ScatteredPaths> mPaths;
    /// The clouds of the frames looked at, for their own renders (RenderBackend::look's views live until then).
    std::map<int, std::unique_ptr<CloudVolume>> mLookedVolumes;
};

/// The version of the Embree library loaded ("3.13.5"), as a device of its
/// own reports it. Throws Error when Embree cannot create a device.
std::string embreeVersion();

} // namespace vfield
