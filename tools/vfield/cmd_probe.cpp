// vfield probe MESH --points FILE.csv: the field's force at given points.

#include "field_cli_options.h"

#include <vfield/core/error.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace vfield::cli {

namespace {

/// Reads one "x,y,z" per line; blank lines and '#' comments are skipped, and
/// so is a first line that is a header (no number in it).
std::vector<Vec3d> readPoints(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw FileError(path, "cannot open for reading");
    std::vector<Vec3d> points;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream fields(line);
        Vec3d p;
        std::string rest;
        if (!(fields >> p[0] >> p[1] >> p[2]) || (fields >> rest)) {
            if (number == 1 && line.find_first_of("0123456789") == std::string::npos) continue;
            throw ParseError(path, "line " + std::to_string(number), "expected three numbers x,y,z");
        }
        points.push_back(p);
    }
    return points;
}

} // namespace

Runner registerProbe(CLI::App& app, const GlobalOptions& global)
{
    struct Options {
        FieldCliOptions field;
        std::string pointsPath;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("probe", "Print the field's force at points read from a CSV file");
    addFieldOptions(*command, o->field);
    command->add_option("--points", o->pointsPath, "CSV file, one x,y,z per line (object units)")->required();

    return [o, &global] {
        const std::vector<Vec3d> points = readPoints(o->pointsPath);
        const MeshAndField built = loadMeshAndBuildField(o->field, global);
        std::printf("x,y,z,fx,fy,fz,level,surface\n");
        for (const Vec3d& p : points) {
            const FieldSample s = built.field.sample(p);
            std::printf("%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d\n", p[0], p[1], p[2], s.force[0], s.force[1], s.force[2], s.level,
                        s.isSurface ? 1 : 0);
        }
    };
}

} // namespace vfield::cli
