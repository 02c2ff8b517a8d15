#include "cli_values.h"

#include <vfield/core/error.h>

#include <cctype>
#include <cmath>
#include <sstream>

namespace vfield::cli {

namespace {

/// The value of text if it is an integer and nothing else.
std::optional<int> wholeInteger(const std::string& text)
{
    std::istringstream in(text);
    int value = 0;
    if (!(in >> value) || !in.eof()) return std::nullopt;
    return value;
}

/// Checks the image values against ImageSettings::validate, as a usage error of option.
void checkImage(const ImageSettings& image, const std::string& option)
{
    try {
        image.validate();
    } catch (const OptionError& e) {
        throw CLI::ValidationError(option, e.detail());
    }
}

} // namespace

void addFrameRangeOption(CLI::App& command, std::optional<FrameRange>& range, const std::string& help)
{
    command
        .add_option_function<std::string>(
            "--frames",
            [&range](const std::string& text) {
                const std::size_t dash = text.find('-', 1);
                const std::optional<int> first = wholeInteger(text.substr(0, dash));
                const std::optional<int> last = dash == std::string::npos ? first : wholeInteger(text.substr(dash + 1));
                if (!first || !last) throw CLI::ValidationError("--frames", "expected A-B or A, got '" + text + "'");
                if (*last < *first) throw CLI::ValidationError("--frames", "the range " + text + " ends before it starts");
                range = FrameRange{*first, *last};
            },
            help)
        ->type_name("A-B");
}

void addSplitRuleOption(CLI::App& command, std::optional<SplitRule>& rule)
{
    command
        .add_option_function<std::string>(
            "--split-rule",
            [&rule](const std::string& text) {
                if (text == "normalCone") rule = SplitRule::NormalCone;
                else if (text == "paper") rule = SplitRule::Paper;
                else throw CLI::ValidationError("--split-rule", "expected normalCone or paper, got '" + text + "'");
            },
            "When an octree node is split: normalCone (also while two of its triangles face more than 90 degrees "
            "apart, so thin parts push away on both sides) or paper (the triangle count only, as the paper) "
            "[default: normalCone; for a scene, its objects' repulsion.splitRule]")
        ->type_name("normalCone|paper");
}

void addRepulsionMethodOption(CLI::App& command, std::optional<RepulsionMethod>& method)
{
    command
        .add_option_function<std::string>(
            "--repulsion-method",
            [&method](const std::string& text) {
                for (const RepulsionMethod m :
                     {RepulsionMethod::Octree, RepulsionMethod::Distance, RepulsionMethod::PotentialFlow})
                    if (text == repulsionMethodName(m)) method = m;
                if (!method)
                    throw CLI::ValidationError("--repulsion-method",
                                               "expected octree, distance or potentialFlow, got '" + text + "'");
            },
            "How every object's repulsive field is made: octree (the paper's), distance (from the signed distance) "
            "or potentialFlow (the clouds' wind flowing around static objects) [default: each object's "
            "repulsion.method]")
        ->type_name("octree|distance|potentialFlow");
}

void addMaxMemoryOption(CLI::App& command, std::optional<double>& bytes)
{
    command
        .add_option_function<std::string>(
            "--max-memory",
            [&bytes](const std::string& text) {
                std::istringstream in(text);
                double value = 0.0;
                std::string unit;
                const bool number = bool(in >> value);
                in >> unit;
                const std::string units = "KMGT";
                const std::size_t prefix =
                    unit.empty() ? std::string::npos : units.find(char(std::toupper(static_cast<unsigned char>(unit[0]))));
                const std::size_t power = unit.empty() ? 0 : prefix + 1;
                const bool known = unit.empty() || (prefix != std::string::npos &&
                                                    (unit.size() == 1 || unit.substr(1) == "iB" || unit.substr(1) == "B"));
                if (!number || !in.eof() || !(value > 0.0) || !known)
                    throw CLI::ValidationError("--max-memory", "expected a size such as 16G or 512M, got '" + text + "'");
                bytes = value * std::pow(1024.0, double(power));
            },
            "Refuse a scene or mesh estimated to need more memory than this, before loading it (scenes/README.md) "
            "[default: the memory available]")
        ->type_name("SIZE");
}

void ImageOverrides::applyTo(ImageSettings& image) const
{
    if (width) image.width = *width;
    if (height) image.height = *height;
    if (samplesPerPixel) image.samplesPerPixel = *samplesPerPixel;
    if (transparentSky) image.transparentSky = true;
}

void addImageOverrideOptions(CLI::App& command, ImageOverrides& overrides)
{
    command
        .add_option_function<std::string>(
            "--resolution",
            [&overrides](const std::string& text) {
                const std::size_t x = text.find('x');
                const std::optional<int> w = x == std::string::npos ? std::nullopt : wholeInteger(text.substr(0, x));
                const std::optional<int> h = x == std::string::npos ? std::nullopt : wholeInteger(text.substr(x + 1));
                if (!w || !h) throw CLI::ValidationError("--resolution", "expected WxH, e.g. 1280x720, got '" + text + "'");
                ImageSettings image;
                image.width = *w;
                image.height = *h;
                checkImage(image, "--resolution");
                overrides.width = w;
                overrides.height = h;
            },
            "Image size WxH [default: the scene's]")
        ->type_name("WxH");
    command
        .add_option_function<int>(
            "--spp",
            [&overrides](int spp) {
                ImageSettings image;
                image.samplesPerPixel = spp;
                checkImage(image, "--spp");
                overrides.samplesPerPixel = spp;
            },
            "Samples per pixel [default: the scene's]")
        ->type_name("N");
    command.add_flag("--transparent-sky", overrides.transparentSky,
                     "Draw the sky as RGB 0, alpha 0 (premultiplied), to composite over a plate [default: the scene's]");
}

} // namespace vfield::cli
