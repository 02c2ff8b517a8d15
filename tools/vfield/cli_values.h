#pragma once
// Values that several subcommands take, each parsed once while the command
// line is parsed (a bad one is a usage error, exit 2) into typed options.

#include "command.h"

#include <vfield/field/octree_field.h>
#include <vfield/field/repulsion_field.h>
#include <vfield/render/render_settings.h>

#include <optional>

namespace vfield::cli {

struct FrameRange {
    int first = 0, last = 0;
};

/// --frames A-B or A.
void addFrameRangeOption(CLI::App& command, std::optional<FrameRange>& range, const std::string& help);

/// --split-rule normalCone|paper, for every command that builds a field.
void addSplitRuleOption(CLI::App& command, std::optional<SplitRule>& rule);
/// --repulsion-method for every object of a scene.
void addRepulsionMethodOption(CLI::App& command, std::optional<RepulsionMethod>& method);

/// --max-memory SIZE (bytes, or with K, M, G, T: binary multiples) for the commands that simulate.
void addMaxMemoryOption(CLI::App& command, std::optional<double>& bytes);

/// --resolution WxH and --spp N: changes to the scene's image settings,
/// checked against ImageSettings' own limits.
struct ImageOverrides {
    std::optional<int> width, height, samplesPerPixel;
    bool transparentSky = false;
    /// Applies the given values to image (the scene's copy every back-end reads).
    void applyTo(ImageSettings& image) const;
};
void addImageOverrideOptions(CLI::App& command, ImageOverrides& overrides);

} // namespace vfield::cli
