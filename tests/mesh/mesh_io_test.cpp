#include "test_meshes.h"

#include <vfield/core/error.h>
#include <vfield/mesh/mesh_io.h>
#include <vfield/mesh/procedural.h>

#include <catch2/catch.hpp>

#include <fstream>
#include <random>

using namespace vfield;

namespace {

std::string writeFile(const std::string& dir, const std::string& name, const std::string& bytes)
{
    const std::string path = dir + "/" + name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

/// Loading must fail with one line that starts with the file's path.
void requireRejected(const std::string& path, const std::string& expectedText = "")
{
    try {
        loadMesh(path);
        FAIL("loaded " << path);
    } catch (const FileError& e) {
        const std::string message = e.what();
        INFO(message);
        CHECK(message.rfind(path + ": ", 0) == 0);
        CHECK(message.find('\n') == std::string::npos);
        if (!expectedText.empty()) CHECK(message.find(expectedText) != std::string::npos);
    }
}

std::string readWhole(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void requireUnitTetrahedron(const TriangleMesh& mesh, const Vec3d& offset = Vec3d(0.0))
{
    CHECK(mesh.points.size() == 4);
    CHECK(mesh.triangleCount() == 4);
    CHECK(analyzeTopology(mesh).isClosed());
    CHECK(signedVolume(mesh) == Approx(1.0 / 6.0));
    CHECK(mesh.bounds().min() == offset);
}

} // namespace

TEST_CASE("mesh io: OBJ quads are triangulated and shared corners merged", "[mesh][io]")
{
    const TriangleMesh cube = loadMesh(test::dataPath("cube_quads.obj"));
    CHECK(cube.points.size() == 8);
    CHECK(cube.triangleCount() == 12);
    CHECK(analyzeTopology(cube).isClosed());
    CHECK(signedVolume(cube) == Approx(1.0));
}

TEST_CASE("mesh io: PLY loads and its zero-area triangle is dropped and counted", "[mesh][io]")
{
    MeshLoadReport report;
    requireUnitTetrahedron(loadMesh(test::dataPath("tetra.ply"), &report));
    CHECK(report.degenerateTrianglesRemoved == 1);
}

TEST_CASE("mesh io: ASCII STL loads with its per-facet corners merged", "[mesh][io]")
{
    requireUnitTetrahedron(loadMesh(test::dataPath("tetra.stl")));
}

TEST_CASE("mesh io: glTF loads with its node transform applied", "[mesh][io]")
{
    requireUnitTetrahedron(loadMesh(test::dataPath("tetra_translated.gltf")), Vec3d(10, 0, 0));
}

TEST_CASE("mesh io: an OBJ written by vfield reads back the same", "[mesh][io]")
{
    const std::string dir = test::scratchDir("obj-roundtrip");
    const TriangleMesh terrain = makeTerrain({});
    saveObj(terrain, dir + "/terrain.obj");
    const TriangleMesh back = loadMesh(dir + "/terrain.obj");
    REQUIRE(back.triangleCount() == terrain.triangleCount());
    CHECK(back.points.size() == terrain.points.size());
    int differences = 0; // assimp may renumber points: compare the corners
    for (std::size_t t = 0; t < terrain.triangleCount(); ++t)
        for (int c = 0; c < 3; ++c)
            if (back.points[back.triangles[t][c]] != terrain.points[terrain.triangles[t][c]]) ++differences;
    CHECK(differences == 0);
}

TEST_CASE("mesh io: missing or empty or non-regular files are refused", "[mesh][io]")
{
    const std::string dir = test::scratchDir("bad-files");
    requireRejected(dir + "/missing.obj", "no such file");
    requireRejected(writeFile(dir, "empty.obj", ""), "empty file");
    requireRejected(dir, "not a regular file");
}

TEST_CASE("mesh io: non-finite coordinates are refused", "[mesh][io]")
{
    const std::string dir = test::scratchDir("non-finite");
    requireRejected(writeFile(dir, "nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n"), "non-finite");
    requireRejected(writeFile(dir, "inf.ply",
                              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1e999 0\n3 0 1 2\n"),
                    "non-finite");
}

TEST_CASE("mesh io: out-of-range indices are refused", "[mesh][io]")
{
    const std::string dir = test::scratchDir("bad-indices");
    requireRejected(writeFile(dir, "index.ply",
                              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"));
    requireRejected(writeFile(dir, "index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"));
}

TEST_CASE("mesh io: a PLY header that never ends or breaks the grammar is refused at once", "[mesh][io]")
{
    const std::string dir = test::scratchDir("endless-header");
    std::string header = "ply\nformat ascii 1.0\n";
    while (header.size() < 100000) header += "comment this header goes on and on\n";
    requireRejected(writeFile(dir, "endless.ply", header), "end_header");
    requireRejected(writeFile(dir, "cut.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), "end_header");
    requireRejected(writeFile(dir, "notply.ply", "hello\n"), "not a PLY file");
    // An 'end_header' without its line break made assimp loop forever.
    requireRejected(writeFile(dir, "glued.ply", "ply\nformat ascii 1.0\nelement vertex 0\nend_header0 0 0\n"),
                    "PLY header line 4: unexpected 'end_header0'");
    requireRejected(writeFile(dir, "format.ply", "ply\nformat ascii 2.0\nend_header\n"), "PLY header line 2");
}

TEST_CASE("mesh io: truncated files are refused", "[mesh][io]")
{
    const std::string dir = test::scratchDir("truncated");
    // Binary STL: 80-byte header, a count of 10 triangles, data for one.
    std::string stl(80, ' ');
    const uint32_t count = 10;
    stl.append(reinterpret_cast<const char*>(&count), 4);
    stl.append(50, '\0');
    requireRejected(writeFile(dir, "short.stl", stl));
    requireRejected(writeFile(dir, "short.ply",
                              "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n"));
    requireRejected(writeFile(dir, "short.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primi"));
}

TEST_CASE("mesh io: every prefix of a valid file loads or is refused with one line", "[mesh][io]")
{
    // Truncation at any byte must never crash or hang.
    const std::string dir = test::scratchDir("prefixes");
    for (const char* name : {"tetra.ply", "tetra.stl", "cube_quads.obj", "tetra_translated.gltf"}) {
        const std::string whole = readWhole(test::dataPath(name));
        for (std::size_t length = 0; length < whole.size(); ++length) {
            const std::string path = writeFile(dir, std::string("prefix_") + name, whole.substr(0, length));
            try {
                loadMesh(path);
            } catch (const FileError& e) {
                CHECK(std::string(e.what()).rfind(path + ": ", 0) == 0);
            }
        }
    }
}

TEST_CASE("mesh io: random bytes are refused whatever the extension", "[mesh][io]")
{
    const std::string dir = test::scratchDir("random-bytes");
    std::mt19937 random(11);
    for (const char* extension : {".obj", ".ply", ".stl", ".gltf", ".glb", ".fbx", ".xyz"}) {
        for (int trial = 0; trial < 5; ++trial) {
            std::string bytes(200 + 100 * trial, '\0');
            for (char& c : bytes) c = char(random() & 0xff);
            requireRejected(writeFile(dir, "random" + std::to_string(trial) + extension, bytes));
        }
    }
}

TEST_CASE("mesh io: valid files with random bytes changed load or are refused with one line", "[mesh][io]")
{
    const std::string dir = test::scratchDir("mutations");
    std::mt19937 random(5);
    for (const char* name : {"tetra.ply", "tetra.stl", "cube_quads.obj", "tetra_translated.gltf"}) {
        const std::string whole = readWhole(test::dataPath(name));
        for (int trial = 0; trial < 300; ++trial) {
            std::string bytes = whole;
            for (int change = 0; change < 1 + trial % 4; ++change) bytes[random() % bytes.size()] = char(random() & 0xff);
            const std::string path = writeFile(dir, std::string("mutated_") + name, bytes);
            try {
                loadMesh(path);
            } catch (const FileError& e) {
                CHECK(std::string(e.what()).rfind(path + ": ", 0) == 0);
            }
        }
    }
}

TEST_CASE("mesh io: a header claiming more elements than the file can hold is refused before loading", "[mesh][io]")
{
    // A few hundred bytes claiming billions of elements would have the reader
    // reserve tens of gigabytes for them.
    const std::string dir = test::scratchDir("claimed-counts");
    requireRejected(writeFile(dir, "huge.off", "OFF\n# a comment\n3535352358 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                    "the header claims 3535352358 vertices");
    requireRejected(writeFile(dir, "huge.ply",
                              "ply\nformat ascii 1.0\nelement vertex 4294967295\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                              "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                    "the header claims 4294967295 vertex elements");
    requireRejected(writeFile(dir, "faces.ply",
                              "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\n"
                              "end_header\n" +
                                  std::string(100, '\0')),
                    "the header claims 4000000000 face elements");
    std::string stl(80, 'x');
    const uint32_t claimed = 4000000000u;
    stl.append(reinterpret_cast<const char*>(&claimed), 4);
    stl.append(50, '\0');
    requireRejected(writeFile(dir, "huge.stl", stl), "the header claims 4000000000 triangles");

    // Honest headers still load.
    CHECK(loadMesh(writeFile(dir, "ok.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).triangleCount() == 1);
    CHECK(loadMesh(test::dataPath("tetra.ply")).triangleCount() == 4);
    CHECK(loadMesh(test::dataPath("tetra.stl")).triangleCount() == 4);
}
