#include <vfield/render/render_backend.h>

#include <vfield/core/error.h>
#include <vfield/core/frame_file.h>
#include <vfield/render/frame_image.h>

#include <algorithm>
#include <filesystem>

namespace fs = std::filesystem;

namespace vfield {

CompositeBackend::CompositeBackend(std::vector<std::unique_ptr<RenderBackend>> parts) : mParts(std::move(parts))
{
    if (mParts.size() < 2) throw ValueError("a composite back-end puts two or more back-ends side by side");
    for (const auto& part : mParts) {
        const std::vector<std::string> files = part->frameFiles("", 0);
        if (std::none_of(files.begin(), files.end(), [](const std::string& f) { return fs::path(f).extension() == ".png"; }))
            throw ValueError("the side-by-side images of several back-ends are png: include png in the formats");
    }
}

std::string CompositeBackend::name() const
{
    std::string name;
    for (const auto& part : mParts) name += (name.empty() ? "" : "+") + part->name();
    return name;
}

std::vector<std::string> CompositeBackend::cannotDraw(const RenderSettings& settings) const
{
    std::vector<std::string> lines;
    for (const auto& part : mParts)
        for (const std::string& line : part->cannotDraw(settings)) lines.push_back(line);
    return lines;
}

std::string CompositeBackend::partFolder(const std::string& out, const RenderBackend& part) const
{
    return (fs::path(out) / part.name()).string();
}

std::vector<std::string> CompositeBackend::frameFiles(const std::string& out, int frame) const
{
    std::vector<std::string> files;
    for (const auto& part : mParts)
        for (const std::string& file : part->frameFiles(partFolder(out, *part), frame)) files.push_back(file);
    files.push_back((fs::path(out) / frameFileName("frame", frame, "png")).string());
    return files;
}

void CompositeBackend::prepare()
{
    for (const auto& part : mParts) part->prepare();
}

void CompositeBackend::render(const FrameView& frame, const std::string& out)
{
    std::vector<std::string> pngs;
    for (const auto& part : mParts) {
        const std::string folder = partFolder(out, *part);
        part->render(frame, folder);
        pngs.push_back((fs::path(folder) / frameFileName("frame", frame.frame, "png")).string());
    }
    const std::string sideBySide = (fs::path(out) / frameFileName("frame", frame.frame, "png")).string();
    writeSideBySide(pngs[0], pngs[1], sideBySide);
    for (std::size_t i = 2; i < pngs.size(); ++i) writeSideBySide(sideBySide, pngs[i], sideBySide);
}

int CompositeBackend::framesAround() const
{
    int around = 0;
    for (const auto& part : mParts) around = std::max(around, part->framesAround());
    return around;
}

void CompositeBackend::look(const FrameView& frame)
{
    for (const auto& part : mParts) part->look(frame);
}

std::map<std::string, double> CompositeBackend::secondsByBackend() const
{
    std::map<std::string, double> seconds;
    for (const auto& part : mParts)
        for (const auto& [name, s] : part->secondsByBackend()) seconds[name] += s;
    return seconds;
}

} // namespace vfield
