#pragma once
// Small meshes with hand-computable fields, and the files and runs of the
// vfield command that the tests share.

#include <vfield/mesh/triangle_mesh.h>

#include <string>

namespace vfield::test {

/// Adds the axis-aligned square [x0,x1] x [y0,y1] at height z as two
/// triangles facing +z.
void addSquareFacingUp(TriangleMesh& mesh, double x0, double y0, double x1, double y1, double z);

/// A mesh whose octree (margin 0.25) has the root [0,4]^3 and shows every rule:
/// four small squares facing +z at z = 0.5 inside the level-3 cells of the
/// root's (-,-,-) octant, and one triangle facing +x in its (+,+,+) octant.
TriangleMesh paperFigure3Mesh();

/// Folder of test files shipped with the sources, and a fresh scratch folder.
std::string dataPath(const std::string& name);
std::string scratchDir(const std::string& name);

/// A file's whole contents (empty if it cannot be read).
std::string readTextFile(const std::string& path);

/// How many lines a command printed (its newlines).
int lineCount(const std::string& text);

/// What a run of the vfield command gave.
struct CliRun {
    int exitCode;
    std::string out, err;
};
/// Runs the vfield binary with arguments (a shell-quoted string); its output
/// goes through dir/stdout and dir/stderr.
CliRun runVfieldCli(const std::string& arguments, const std::string& dir);

} // namespace vfield::test
