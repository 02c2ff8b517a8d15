#include "test_meshes.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace vfield::test {

void addSquareFacingUp(TriangleMesh& mesh, double x0, double y0, double x1, double y1, double z)
{
    const auto base = uint32_t(mesh.points.size());
    mesh.points.emplace_back(x0, y0, z);
    mesh.points.emplace_back(x1, y0, z);
    mesh.points.emplace_back(x1, y1, z);
    mesh.points.emplace_back(x0, y1, z);
    mesh.triangles.emplace_back(base, base + 1, base + 2);
    mesh.triangles.emplace_back(base, base + 2, base + 3);
}

TriangleMesh paperFigure3Mesh()
{
    TriangleMesh mesh;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) addSquareFacingUp(mesh, i + 0.25, j + 0.25, i + 0.75, j + 0.75, 0.5);
    const auto base = uint32_t(mesh.points.size());
    mesh.points.emplace_back(3.75, 3.0, 3.0);
    mesh.points.emplace_back(3.75, 3.75, 3.0);
    mesh.points.emplace_back(3.75, 3.75, 3.5);
    mesh.triangles.emplace_back(base, base + 1, base + 2); // normal +x
    return mesh;
}

std::string dataPath(const std::string& name) { return std::string(VFIELD_TEST_DATA_DIR) + "/" + name; }

std::string scratchDir(const std::string& name)
{
    const auto dir = std::filesystem::temp_directory_path() / ("vfield-test-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

std::string readTextFile(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

int lineCount(const std::string& text) { return int(std::count(text.begin(), text.end(), '\n')); }

CliRun runVfieldCli(const std::string& arguments, const std::string& dir)
{
    const std::string out = dir + "/stdout", err = dir + "/stderr";
    const std::string command = std::string(VFIELD_CLI_PATH) + " " + arguments + " >" + out + " 2>" + err;
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readTextFile(out), readTextFile(err)};
}

} // namespace vfield::test
