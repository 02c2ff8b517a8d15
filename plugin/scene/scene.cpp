#include <vfield/scene/scene.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>
#include <vfield/core/field_visitors.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace vfield {

const ObjectSettings* Scene::findObject(const std::string& name) const
{
    for (const ObjectSettings& object : simulation.objects)
        if (object.name == name) return &object;
    return nullptr;
}

void Scene::validate() const
{
    require(version == 1, "version", "this vfield reads scene version 1");
    simulation.validate();
    render.validate();
    if (const auto& follow = render.camera.follow) {
        const ObjectSettings* target = findObject(follow->object);
        require(target && target->isDynamic, "camera",
                "\"follow\" names \"" + follow->object + "\", which is not a dynamic object of the scene");
    }
    for (const CloudSettings& cloud : simulation.clouds) {
        const double voxel = volume.voxelSize;
        const double voxels = 8.0 * cloud.radii[0] * cloud.radii[1] * cloud.radii[2] / (voxel * voxel * voxel);
        require(voxels <= kMaxDensityVoxels, "volume",
                "cloud \"" + cloud.name + "\" would fill about " + std::to_string(uint64_t(voxels)) + " voxels of size " +
                    numberText(voxel) + " (at most 2e9): raise volume.voxelSize");
    }
    validatePart("volume", volume);
}

Scene parseScene(const std::string& text, const std::string& file)
{
    const JsonValue root = parseJson(text, file);
    Scene scene = readFields<Scene>(root, std::filesystem::path(file).parent_path().string());
    scene.path = file;
    // The density's defaults follow the clouds' particles, resolved once here.
    double radii = 0.0, particles = 0.0;
    for (const CloudSettings& cloud : scene.simulation.clouds) {
        radii += cloud.particleRadius * double(cloud.count);
        particles += double(cloud.count);
    }
    scene.volume = scene.volume.resolved(particles > 0 ? radii / particles : 1.0);
    validateAt(root, [&] { scene.validate(); });
    return scene;
}

namespace {

/// The tokens of a JSON pointer, unescaped ("~1" is '/', "~0" is '~').
std::vector<std::string> pointerTokens(const std::string& pointer)
{
    std::vector<std::string> tokens;
    for (std::size_t at = 1; at <= pointer.size();) {
        const std::size_t end = std::min(pointer.find('/', at), pointer.size());
        std::string token;
        for (std::size_t i = at; i < end; ++i) {
            if (pointer[i] == '~' && i + 1 < end && (pointer[i + 1] == '0' || pointer[i + 1] == '1')) {
                token += pointer[++i] == '0' ? '~' : '/';
            } else {
                token += pointer[i];
            }
        }
        tokens.push_back(token);
        at = end + 1;
    }
    return tokens;
}

/// Sets value at the place the tokens from `at` on name below node. "*"
/// stands for every element of an array; below one, an element whose path
/// passes a false (an object without a field) is left alone, and true
/// counts as {} (its defaults).
void setAt(nlohmann::json& node, const std::vector<std::string>& tokens, std::size_t at, const nlohmann::json& value,
           bool underWildcard)
{
    if (at == tokens.size()) {
        node = value;
        return;
    }
    const std::string& token = tokens[at];
    if (node.is_boolean()) {
        if (!node.get<bool>() && underWildcard) return;
        if (node.get<bool>()) node = nlohmann::json::object();
    }
    if (token == "*") {
        if (!node.is_array()) throw ValueError("\"*\" stands for the elements of an array, and " + node.dump() + " is none");
        for (nlohmann::json& element : node) setAt(element, tokens, at + 1, value, true);
    } else if (node.is_array()) {
        const bool isIndex = !token.empty() && token.find_first_not_of("0123456789") == std::string::npos && token.size() < 10;
        const std::size_t index = isIndex ? std::stoul(token) : node.size() + 1;
        if (token == "-" || index == node.size()) node.push_back(nullptr);
        else if (index > node.size()) throw ValueError("no element " + token + " in an array of " + std::to_string(node.size()));
        setAt(node[token == "-" ? node.size() - 1 : index], tokens, at + 1, value, underWildcard);
    } else if (node.is_object() || node.is_null()) {
        setAt(node[token], tokens, at + 1, value, underWildcard);
    } else {
        throw ValueError("no key \"" + token + "\" in " + node.dump().substr(0, 40));
    }
}

} // namespace

Scene loadScene(const std::string& path, const std::vector<SceneOverride>& overrides)
{
    const std::string text = readFileBytes(path);
    if (overrides.empty()) return parseScene(text, path);

    nlohmann::json json = parseJson(text, path).raw(); // syntax errors name the file's line and column
    for (const SceneOverride& o : overrides) {
        const std::string what = "override " + o.pointer + "=" + o.value + ": ";
        if (o.pointer.empty() || o.pointer[0] != '/') throw ValueError(what + "a JSON pointer starts with '/'");
        nlohmann::json value;
        try {
            value = parseJson(o.value, "override").raw();
        } catch (const ParseError&) {
            throw ValueError(what + "the value is not JSON (a string needs its quotes)");
        }
        try {
            setAt(json, pointerTokens(o.pointer), 0, value, false);
        } catch (const ValueError& e) {
            throw ValueError(what + "no such place in the scene (" + e.what() + ")");
        }
    }
    return parseScene(json.dump(2), path);
}

} // namespace vfield
