#include <vfield/mesh/mesh_io.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

namespace fs = std::filesystem;

namespace vfield {

namespace {

std::string lowerExtension(const std::string& path)
{
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

/// assimp 5.2 loops forever on some malformed PLY headers (one that never
/// ends, an 'end_header' not followed by a line break, ...): check the header
/// against the PLY grammar before handing the file over.
void checkPlyHeader(const std::string& path)
{
    constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
    std::ifstream in(path, std::ios::binary);
    std::string head(kMaxHeaderBytes, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));

    std::size_t begin = 0;
    for (int number = 1;; ++number) {
        const std::size_t end = head.find('\n', begin);
        if (end == std::string::npos) throw FileError(path, "PLY header does not end (no 'end_header' line in the first 64 KiB)");
        std::string line = head.substr(begin, end - begin);
        begin = end + 1;
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
        const std::string keyword = line.substr(0, line.find(' '));
        const std::string where = "PLY header line " + std::to_string(number) + ": ";
        if (number == 1) {
            if (line != "ply") throw FileError(path, "not a PLY file (it does not start with 'ply')");
        } else if (number == 2) {
            if (line != "format ascii 1.0" && line != "format binary_little_endian 1.0" && line != "format binary_big_endian 1.0")
                throw FileError(path, where + "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
        } else if (line == "end_header") {
            return;
        } else if (keyword != "comment" && keyword != "obj_info" && keyword != "element" && keyword != "property") {
            throw FileError(path, where + "unexpected '" + keyword.substr(0, 32) + "'");
        }
    }
}

void checkReadableFile(const std::string& path)
{
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw FileError(path, "no such file");
    if (!fs::is_regular_file(status)) throw FileError(path, "not a regular file");
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw FileError(path, "cannot open for reading");
    if (fs::file_size(path, ec) == 0) throw FileError(path, "empty file");
}

void recomputePrimitiveTypes(aiMesh& mesh, unsigned meshIndex, const std::string& path)
{
    unsigned types = 0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const unsigned n = mesh.mFaces[f].mNumIndices;
        if (n == 0)
            throw FileError(path, "mesh " + std::to_string(meshIndex) + ", face " + std::to_string(f) + " has no vertices");
        types |= n == 1   ? aiPrimitiveType_POINT
                 : n == 2 ? aiPrimitiveType_LINE
                 : n == 3 ? aiPrimitiveType_TRIANGLE
                          : aiPrimitiveType_POLYGON;
    }
    mesh.mPrimitiveTypes = types;
}

void appendNodeMeshes(const aiScene& scene, const std::string& path, TriangleMesh& out, MeshLoadReport& report)
{
    // aiProcess_PreTransformVertices has baked node transforms into the meshes.
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
        const aiMesh& mesh = *scene.mMeshes[m];
        const auto base = static_cast<uint32_t>(out.points.size());
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D& p = mesh.mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                throw FileError(path,
                                "mesh " + std::to_string(m) + ", vertex " + std::to_string(v) + " has a non-finite coordinate");
            out.points.emplace_back(p.x, p.y, p.z);
        }
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
            const aiFace& face = mesh.mFaces[f];
            if (face.mNumIndices != 3) {
                ++report.nonTriangleFacesIgnored;
                continue;
            }
            for (unsigned corner = 0; corner < 3; ++corner)
                if (face.mIndices[corner] >= mesh.mNumVertices)
                    throw FileError(path, "mesh " + std::to_string(m) + ", face " + std::to_string(f) + " uses vertex " +
                                              std::to_string(face.mIndices[corner]) + " of " + std::to_string(mesh.mNumVertices));
            out.triangles.emplace_back(base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]);
        }
    }
}

} // namespace

std::vector<std::string> MeshLoadReport::lines(const std::string& path) const
{
    std::vector<std::string> lines;
    if (degenerateTrianglesRemoved > 0)
        lines.push_back(path + ": dropped " + std::to_string(degenerateTrianglesRemoved) + " zero-area triangles");
    if (nonTriangleFacesIgnored > 0)
        lines.push_back(path + ": ignored " + std::to_string(nonTriangleFacesIgnored) + " points and lines");
    if (orientation.changed())
        lines.push_back(path + ": closed mesh oriented outward (" + std::to_string(orientation.piecesTurnedOut) +
                        " inside-out pieces turned, " + std::to_string(orientation.trianglesFlipped) +
                        " triangles flipped to agree with their neighbours); repulsion.flipNormals turns it around");
    return lines;
}

TriangleMesh loadMesh(const std::string& path, MeshLoadReport* reportOut)
{
    checkReadableFile(path);
    if (lowerExtension(path) == ".ply") checkPlyHeader(path);

    Assimp::Importer importer;
    // Only positions matter: dropping normals, UVs and colours lets assimp keep
    // one vertex per position instead of one per corner.
    importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                            aiComponent_COLORS | aiComponent_TEXCOORDS | aiComponent_BONEWEIGHTS |
                                                            aiComponent_ANIMATIONS | aiComponent_TEXTURES | aiComponent_LIGHTS |
                                                            aiComponent_CAMERAS | aiComponent_MATERIALS);
    const aiScene* scene =
        importer.ReadFile(path, aiProcess_RemoveComponent | aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure);
    if (scene) {
        // assimp's triangulation trusts each mesh's primitive flags and aborts
        // the process (an assertion) when a malformed file left them wrong:
        // recompute them from the faces before triangulating.
        for (unsigned m = 0; m < scene->mNumMeshes; ++m) recomputePrimitiveTypes(*scene->mMeshes[m], m, path);
        scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
    }
    if (!scene) {
        std::string why = importer.GetErrorString();
        why.erase(std::remove(why.begin(), why.end(), '\n'), why.end());
        throw FileError(path, "cannot read mesh: " + (why.empty() ? std::string("unknown format") : why));
    }

    MeshLoadReport report;
    TriangleMesh mesh;
    appendNodeMeshes(*scene, path, mesh, report);
    mergeIdenticalPoints(mesh);
    report.degenerateTrianglesRemoved = removeDegenerateTriangles(mesh);
    if (mesh.empty()) throw FileError(path, "the file holds no triangle of non-zero area");
    report.orientation = orientClosedPiecesOutward(mesh);
    if (reportOut) *reportOut = report;
    return mesh;
}

void saveObj(const TriangleMesh& mesh, const std::string& path)
{
    writeFileAtomically(path, [&](const std::string& temporary) {
        std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(temporary.c_str(), "wb"), &std::fclose);
        if (!file) throw FileError(path, "cannot open for writing");
        std::fprintf(file.get(), "# vfield mesh: %zu points, %zu triangles\n", mesh.points.size(), mesh.triangles.size());
        for (const Vec3f& p : mesh.points) std::fprintf(file.get(), "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
        for (const Vec3ui& t : mesh.triangles) std::fprintf(file.get(), "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
        if (std::fflush(file.get()) != 0 || std::ferror(file.get())) throw FileError(path, "cannot write");
    });
}

} // namespace vfield
