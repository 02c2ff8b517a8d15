#include <vfield/run/render_backends.h>

#include <vfield/core/error.h>
#include <vfield/render/embree/embree_backend.h>
#include <vfield/render/povray/povray_backend.h>

#include <tbb/task_arena.h>

#include <filesystem>

namespace vfield {

namespace {

std::unique_ptr<RenderBackend> makeEmbree(const BackendInputs& s)
{
    std::vector<std::string> objectNames;
    for (const ObjectSettings& object : s.scene->simulation.objects) objectNames.push_back(object.name);
    return std::make_unique<EmbreeBackend>(s.scene->render, *s.surfaces, *s.materials, s.terrainLow, s.terrainHigh, s.formats,
                                           std::move(objectNames));
}

std::unique_ptr<RenderBackend> makePovray(const BackendInputs& s)
{
    if (s.formats != std::vector<std::string>{"png"}) throw ValueError("the POV-Ray back-end writes png images only");
    std::vector<PovrayMesh> meshes;
    const std::vector<ObjectSettings>& objects = s.scene->simulation.objects;
    for (std::size_t i = 0; i < objects.size(); ++i)
        meshes.push_back({int(i), &(*s.meshes)[i], s.materials->at(int(i)),
                          objects[i].isDynamic ? std::nullopt : std::optional<Transform>(objects[i].transform)});
    return std::make_unique<PovrayBackend>(std::move(meshes), s.terrainLow, s.terrainHigh, s.scene->render, s.scene->povray,
                                           (std::filesystem::path(s.outputDir) / "povray-scene").string(),
                                           tbb::this_task_arena::max_concurrency());
}

std::unique_ptr<RenderBackend> makeBoth(const BackendInputs& s)
{
    std::vector<std::unique_ptr<RenderBackend>> parts;
    parts.push_back(makeEmbree(s));
    BackendInputs povray = s;
    povray.formats = {"png"};
    parts.push_back(makePovray(povray));
    return std::make_unique<CompositeBackend>(std::move(parts));
}

struct Entry {
    const char* name;
    std::unique_ptr<RenderBackend> (*make)(const BackendInputs&);
};
const Entry kBackends[] = {{"embree", makeEmbree}, {"povray", makePovray}, {"both", makeBoth}};

} // namespace

std::vector<std::string> renderBackendNames()
{
    std::vector<std::string> names;
    for (const Entry& entry : kBackends) names.push_back(entry.name);
    return names;
}

std::unique_ptr<RenderBackend> makeRenderBackend(const std::string& name, const BackendInputs& setup)
{
    for (const Entry& entry : kBackends)
        if (name == entry.name) return entry.make(setup);
    throw ValueError("unknown back-end '" + name + "' (embree, povray or both)");
}

} // namespace vfield
