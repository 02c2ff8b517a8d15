#include <vfield/render/povray/povray_scene.h>

#include <vfield/core/error.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace vfield {

namespace {

/// (x, y, z) in vfield's right-handed world -> POV-Ray's left-handed one.
Vec3d mirrored(const Vec3d& v) { return Vec3d(v[0], v[1], -v[2]); }

/// "<x, y, z>" with enough digits for the value's use: 7 for mesh data
/// (floats), 10 for placements and colours.
std::string vec(const Vec3d& v, int digits = 10)
{
    char text[128];
    std::snprintf(text, sizeof text, "<%.*g, %.*g, %.*g>", digits, v[0] + 0.0, digits, v[1] + 0.0, digits, v[2] + 0.0);
    return text;
}

std::string num(double value)
{
    char text[48];
    std::snprintf(text, sizeof text, "%.10g", value + 0.0);
    return text;
}

void writeMesh(std::ostream& out, const PovrayMesh& m, double terrainLow, double terrainHigh)
{
    const TriangleMesh& mesh = *m.mesh;
    const std::vector<Vec3f> objectNormals = vertexNormals(mesh);
    std::vector<Vec3d> points(mesh.points.size()), normals(mesh.points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        points[i] = m.placement ? m.placement->worldFromObject(Vec3d(mesh.points[i])) : Vec3d(mesh.points[i]);
        normals[i] = m.placement ? m.placement->rotateToWorld(Vec3d(objectNormals[i])) : Vec3d(objectNormals[i]);
    }
    const bool perPointColour = m.material.kind == SurfaceMaterial::Kind::Terrain;

    out << "#declare VF_Object_" << m.object << " = mesh2 {\n";
    out << "  vertex_vectors { " << points.size();
    for (const Vec3d& p : points) out << ",\n    " << vec(mirrored(p), 7);
    out << "\n  }\n  normal_vectors { " << normals.size();
    for (const Vec3d& n : normals) out << ",\n    " << vec(mirrored(n), 7);
    out << "\n  }\n";
    if (perPointColour) {
        out << "  texture_list { " << points.size();
        for (std::size_t i = 0; i < points.size(); ++i)
            out << ",\n    texture { pigment { rgb "
                << vec(surfaceAlbedo(m.material, points[i], normals[i], terrainLow, terrainHigh,
                                     surfaceNoise(m.material, points[i])),
                       5)
                << " } }";
        out << "\n  }\n";
    }
    out << "  face_indices { " << mesh.triangleCount();
    for (const Vec3ui& t : mesh.triangles) {
        out << ",\n    <" << t[0] << ", " << t[1] << ", " << t[2] << ">";
        if (perPointColour) out << ", " << t[0] << ", " << t[1] << ", " << t[2];
    }
    out << "\n  }\n";
    if (!perPointColour)
        out << "  texture { pigment { rgb " << vec(surfaceAlbedo(m.material, Vec3d(0.0), Vec3d(0, 1, 0), 0, 1, SurfaceNoise{}), 5)
            << " } }\n";
    out << "}\n";
}

/// POV-Ray's matrix for a pose, in mirrored space: M R s (p) + M t with M the
/// z mirror, applied to points already mirrored (M p), is (M R M) s p' + M t.
/// POV-Ray's rows are the images of its x, y and z axes.
std::string poseMatrix(const Transform& pose)
{
    std::ostringstream out;
    out << "matrix <";
    for (int axis = 0; axis < 3; ++axis) {
        Vec3d unit(0.0);
        unit[axis] = 1.0;
        const Vec3d image = mirrored(pose.rotateToWorld(mirrored(unit))) * pose.scale;
        out << (axis ? ",\n      " : "") << num(image[0]) << ", " << num(image[1]) << ", " << num(image[2]);
    }
    const Vec3d t = mirrored(pose.translation);
    out << ",\n      " << num(t[0]) << ", " << num(t[1]) << ", " << num(t[2]) << ">";
    return out.str();
}

} // namespace

std::string povrayMeshesText(const std::vector<PovrayMesh>& meshes, double terrainLow, double terrainHigh)
{
    std::ostringstream out;
    out << "// vfield: the scene's meshes for POV-Ray 3.7, points mirrored in z (POV-Ray is left-handed).\n"
           "// Static meshes are in world space, dynamic ones in object space.\n";
    for (const PovrayMesh& mesh : meshes) {
        if (!mesh.mesh) throw ValueError("a POV-Ray mesh without its triangles");
        writeMesh(out, mesh, terrainLow, terrainHigh);
    }
    return out.str();
}

std::string povrayFrameText(const PovrayFrame& f)
{
    if (!f.settings) throw ValueError("a POV-Ray frame needs render settings");
    const RenderSettings& s = *f.settings;
    const Camera& camera = f.camera;
    std::ostringstream out;
    out << "// vfield: frame " << f.frame << " for POV-Ray 3.7. Coordinates are vfield's mirrored in z.\n"
        << "#version 3.7;\n"
        << "global_settings { assumed_gamma 1.0 max_trace_level 8 }\n\n";

    const double planeHeight = 2.0 * camera.tanHalfFov();
    out << "camera {\n  perspective\n  location " << vec(mirrored(camera.position())) << "\n  direction "
        << vec(mirrored(camera.forward())) << "\n  right " << vec(mirrored(camera.right()) * (planeHeight * camera.aspect()))
        << "\n  up " << vec(mirrored(camera.up()) * planeHeight) << "\n}\n\n";

    // Sky: vfield's gradient, smoothstep(0, 0.5, y) from horizon to zenith.
    const Vec3d horizon = s.sky.horizonColor * s.sky.intensity, zenith = s.sky.zenithColor * s.sky.intensity;
    out << "sky_sphere {\n  pigment {\n    function { pow(min(max(2 * y, 0), 1), 2) * (3 - 2 * min(max(2 * y, 0), 1)) }\n"
        << "    color_map { [0 rgb " << vec(horizon) << "] [1 rgb " << vec(zenith) << "] }\n  }\n}\n\n";

    const Vec3d toSun = s.sun.direction.unitSafe();
    out << "light_source {\n  " << vec(mirrored(toSun) * 1e6) << "\n  color rgb " << vec(s.sun.color * (s.sun.intensity / M_PI))
        << "\n  parallel point_at <0, 0, 0>\n  media_interaction on media_attenuation on\n}\n";
    // The sky on surfaces: ambient A plus a shadowless overhead light C, so that
    // A + C n_y meets vfield's sky light facing up (n_y = 1) and sideways (n_y = 0).
    const Vec3d skySideways = skyLightOnSurface(s.sky, Vec3d(1, 0, 0)), skyUp = skyLightOnSurface(s.sky, Vec3d(0, 1, 0));
    out << "light_source {\n  <0, 1e6, 0>\n  color rgb " << vec(skyUp - skySideways)
        << "\n  parallel point_at <0, 0, 0>\n  shadowless media_interaction off\n}\n";
    out << "#default { finish { ambient rgb " << vec(skySideways) << " diffuse 1 specular 0 phong 0 } }\n\n";

    out << "#include \"" << f.meshInclude << "\"\n";
    for (int object : f.staticObjects) out << "object { VF_Object_" << object << " }\n";
    for (const auto& [object, pose] : f.dynamicPoses)
        out << "object { VF_Object_" << object << "\n  " << poseMatrix(pose) << "\n}\n";

    if (f.cloud && f.cloud->placement.densityScale > 0.0) {
        const PovrayCloud& cloud = *f.cloud;
        const MediumSettings& medium = s.medium;
        // POV-Ray's df3 values run over [0, 1]: coefficients carry the density scale.
        const double sigmaT = medium.extinction * cloud.placement.densityScale;
        const double sigmaS = sigmaT * medium.albedo;
        // POV-Ray's phase functions average 1 over the sphere (vfield's integrate
        // to 1: a factor 4 pi) and its lights carry 1/pi: the scattering colour is
        // sigma_s / 4, and `extinction 4` keeps its share of the extinction sigma_s.
        // The sky's light as vfield's fast integrator takes it, without the
        // ground's bounce (the export knows no surface radiance).
        const Vec3d skyMean = cloudAmbientRadiance(s.sky, s.sky.horizonColor * s.sky.intensity);
        const BBoxd& box = cloud.placement.worldBounds;
        const Vec3d size = box.extents();
        const int finalSamples = std::clamp(int(std::ceil(size.length() / s.integrator.volumeStep)), 8, 400);
        const int samples = f.quality == PovrayQuality::Preview ? std::max(8, finalSamples / 4) : finalSamples;
        out << "\nbox { <0, 0, 0>, <1, 1, 1>\n  hollow\n  texture { pigment { rgbt 1 } }\n  interior {\n    media {\n"
            << "      method 3 intervals 1 samples " << samples << "\n"
            << "      absorption rgb " << num(sigmaT - sigmaS) << "\n"
            << "      scattering { 5, rgb " << num(sigmaS / 4.0) << " eccentricity " << num(medium.anisotropy)
            << " extinction 4 }\n"
            << "      density { density_file df3 \"" << cloud.df3File << "\" interpolate 1 }\n    }\n";
        // POV-Ray averages the phase functions of every medium a ray is in,
        // whatever they scatter: the sky light's medium carries the same
        // Henyey-Greenstein lobe (scattering nothing) so the sun's stays as it is.
        if (cloud.skyLitPlacement.densityScale > 0.0)
            out << "    media {\n      method 3 intervals 1 samples " << samples << "\n"
                << "      emission rgb "
                << vec(skyMean * (medium.extinction * medium.albedo * cloud.skyLitPlacement.densityScale)) << "\n"
                << "      scattering { 5, rgb 0 eccentricity " << num(medium.anisotropy) << " }\n"
                << "      density { density_file df3 \"" << cloud.skyLitDf3File << "\" interpolate 1 }\n    }\n";
        out << "  }\n  scale " << vec(Vec3d(size[0], size[1], -size[2])) << "\n"
            << "  translate " << vec(mirrored(box.min())) << "\n}\n";
    }
    return out.str();
}

} // namespace vfield
