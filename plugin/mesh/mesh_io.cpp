#include <vfield/mesh/mesh_io.h>

#include <vfield/core/atomic_file.h>
#include <vfield/core/error.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

namespace fs = std::filesystem;

namespace vfield {

namespace {

std::string lowerExtension(const std::string& path)
{
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

/// A header's claimed element count against what the rest of the file can
/// hold at minBytesEach bytes an element: a tiny file claiming billions would
/// make the loader reserve memory for them all.
void checkClaimedCount(const std::string& path, const std::string& what, uint64_t claimed, uint64_t minBytesEach,
                       uint64_t bodyBytes)
{
    if (minBytesEach == 0 || claimed <= bodyBytes / minBytesEach) return;
    throw FileError(path, "the header claims " + std::to_string(claimed) + " " + what + ", more than the file's " +
                              std::to_string(bodyBytes) + " bytes after its header can hold (at least " +
                              std::to_string(minBytesEach) + " bytes each)");
}

/// Bytes of a PLY scalar type; 0 for an unknown name.
uint64_t plyTypeBytes(const std::string& type)
{
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32") return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

/// assimp 5.2 loops forever on some malformed PLY headers (one that never
/// ends, an 'end_header' not followed by a line break, ...): check the header
/// against the PLY grammar before handing the file over, and each element's
/// count against the bytes after the header (an ASCII value takes at least
/// 2 bytes with its separator, a binary one its type's size; a list at least
/// its count).
void checkPlyHeader(const std::string& path)
{
    constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
    std::ifstream in(path, std::ios::binary);
    std::string head(kMaxHeaderBytes, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));

    struct Element {
        std::string name;
        uint64_t count = 0, minBytes = 0;
    };
    std::vector<Element> elements;
    bool ascii = false;
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
            ascii = line == "format ascii 1.0";
        } else if (line == "end_header") {
            const uint64_t body = fs::file_size(path) - begin;
            for (const Element& e : elements) checkClaimedCount(path, e.name + " elements", e.count, e.minBytes, body);
            return;
        } else if (keyword == "element") {
            std::istringstream words(line.substr(8));
            Element e;
            if (!(words >> e.name >> e.count)) throw FileError(path, where + "expected 'element NAME COUNT'");
            elements.push_back(e);
        } else if (keyword == "property" && !elements.empty()) {
            std::istringstream words(line.substr(9));
            std::string type, countType;
            words >> type;
            if (type == "list") words >> countType;
            const uint64_t bytes = plyTypeBytes(type == "list" ? countType : type);
            elements.back().minBytes += ascii ? 2 : bytes;
        } else if (keyword != "comment" && keyword != "obj_info" && keyword != "element" && keyword != "property") {
            throw FileError(path, where + "unexpected '" + keyword.substr(0, 32) + "'");
        }
    }
}

/// OFF: "OFF" (or a variant such as COFF), then vertex, face and edge counts.
/// A vertex takes at least 6 bytes ("0 0 0\n"), a face at least 2.
void checkOffHeader(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::string head(4096, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    std::istringstream words(head);
    std::string keyword;
    words >> keyword;
    if (keyword.size() < 3 || keyword.compare(keyword.size() - 3, 3, "OFF") != 0) return; // assimp says what it is
    // Comment lines may stand between the keyword and the counts.
    std::string token;
    while (words >> token && token[0] == '#') words.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    uint64_t vertices = 0, faces = 0;
    std::istringstream counts(token);
    if (!(counts >> vertices) || !(words >> faces)) return;
    const uint64_t body = fs::file_size(path) - std::min<uint64_t>(fs::file_size(path), uint64_t(words.tellg()));
    checkClaimedCount(path, "vertices", vertices, 6, body);
    checkClaimedCount(path, "faces", faces, 2, body);
    checkClaimedCount(path, "vertices and faces", vertices + faces / 3, 6, body);
}

/// Binary STL: an 80-byte header, a triangle count, 50 bytes a triangle. A
/// file that starts with "solid" and is not that size is ASCII STL.
void checkBinaryStlHeader(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    char header[84] = {};
    in.read(header, sizeof header);
    if (in.gcount() < 84) return; // too short for binary: assimp reads it as ASCII or refuses it
    uint32_t triangles = 0;
    std::memcpy(&triangles, header + 80, 4); // little-endian, as the format and this machine are
    const uint64_t size = fs::file_size(path);
    if (size == 84 + 50 * uint64_t(triangles)) return;
    if (std::string(header, 5) == "solid") return;
    checkClaimedCount(path, "triangles", triangles, 50, size - 84);
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
    const std::string extension = lowerExtension(path);
    if (extension == ".ply") checkPlyHeader(path);
    else if (extension == ".off") checkOffHeader(path);
    else if (extension == ".stl") checkBinaryStlHeader(path);

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
