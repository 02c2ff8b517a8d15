// `vfield golden` as a technical artist uses it on a shot of their own:
// record, check (exit 0 / 1 / 2, JUnit XML), update with a reason; grids by
// checksum or within a tolerance. The HTML report is opened in a browser by
// tests/golden/report_opens_in_chromium.sh.

#include "test_meshes.h"

#include <vfield/core/vdb_file.h>
#include <vfield/golden/golden_case.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using vfield::test::runVfieldCli;

namespace {

/// A small shot: the feature scene's box of constant density, 96x54, one sample per pixel.
std::string recordBox(const std::string& dir, const std::string& options = "")
{
    const vfield::test::CliRun record =
        runVfieldCli("golden record " + vfield::test::dataPath("../../scenes/features/constant_density_box.json") +
                         " --frames 1 -o " + dir + "/cases/box --resolution 96x54 --spp 1 --why 'a test shot' --quiet " + options,
                     dir);
    INFO(record.err);
    REQUIRE(record.exitCode == 0);
    return dir + "/cases/box";
}

nlohmann::json readCase(const std::string& folder)
{
    return nlohmann::json::parse(vfield::test::readTextFile(folder + "/case.json"));
}
void writeCase(const std::string& folder, const nlohmann::json& json) { std::ofstream(folder + "/case.json") << json.dump(2); }

} // namespace

TEST_CASE("golden: a recorded shot passes its check, fails it once its golden changes, and passes again once updated "
          "with a reason",
          "[golden]")
{
    const std::string dir = vfield::test::scratchDir("golden-record-check-update");
    const std::string box = recordBox(dir);
    const nlohmann::json recorded = readCase(box);
    CHECK(recorded["scene"] ==
          fs::relative(vfield::test::dataPath("../../scenes/features/constant_density_box.json"), box).string());
    CHECK(recorded["images"] == nlohmann::json::array({"images/frame.0001.png"}));
    CHECK(recorded["commands"].back().dump().find("\"--resolution\",\"96x54\",\"--spp\",\"1\"") != std::string::npos);

    vfield::test::CliRun check = runVfieldCli("golden check " + dir + "/cases --junit " + dir + "/junit.xml --quiet", dir);
    INFO(check.out << check.err);
    CHECK(check.exitCode == 0);
    CHECK(vfield::test::readTextFile(dir + "/junit.xml").find("tests=\"1\" failures=\"0\" errors=\"0\"") != std::string::npos);

    // The golden 20% redder in one channel: every pixel of the box differs by more than one 8-bit step.
    const std::string golden = box + "/frame.0001.png";
    OIIO::ImageBuf tinted = OIIO::ImageBufAlgo::mul(OIIO::ImageBuf(golden), {0.8f, 1.0f, 1.0f});
    REQUIRE(tinted.write(golden));
    check = runVfieldCli("golden check " + dir + "/cases --junit " + dir + "/junit.xml --quiet", dir);
    CHECK(check.exitCode == 1);
    CHECK(check.out.find("fail  box") != std::string::npos);
    const std::string junit = vfield::test::readTextFile(dir + "/junit.xml");
    CHECK(junit.find("tests=\"1\" failures=\"1\" errors=\"0\"") != std::string::npos);
    CHECK(junit.find("<failure type=\"golden\" message=\"images/frame.0001.png: mean") != std::string::npos);

    const vfield::test::CliRun update =
        runVfieldCli("golden update " + dir + "/cases --case box --reason 'the test tinted it' --quiet", dir);
    INFO(update.err);
    REQUIRE(update.exitCode == 0);
    const nlohmann::json regenerated = readCase(box)["regenerated"].back();
    CHECK(regenerated["reason"] == "the test tinted it");
    CHECK(regenerated["differences"][0].get<std::string>().rfind("frame.0001.png: mean", 0) == 0);
    CHECK(runVfieldCli("golden check " + box + " --quiet", dir).exitCode == 0);
}

TEST_CASE("golden: check exits 2 when a case cannot run or its file is wrong, naming the command or the JSON path", "[golden]")
{
    const std::string dir = vfield::test::scratchDir("golden-errors");
    fs::create_directories(dir + "/cases/missing_scene");
    std::ofstream(dir + "/cases/missing_scene/case.json") << R"({
  "commands": [["simulate", "@CASE@/no_such_scene.json", "-o", "@OUT@/sim"]],
  "images": ["images/frame.0001.png"],
  "compare": {}
})";
    vfield::test::CliRun check = runVfieldCli("golden check " + dir + "/cases --quiet", dir);
    CHECK(check.exitCode == 2);
    CHECK(check.out.find("error missing_scene") != std::string::npos);
    CHECK(check.out.find("no_such_scene.json") != std::string::npos);

    fs::create_directories(dir + "/bad/percent");
    std::ofstream(dir + "/bad/percent/case.json") << R"({"commands": [], "images": [], "compare": {"failPercent": 200}})";
    check = runVfieldCli("golden check " + dir + "/bad --quiet", dir);
    CHECK(check.exitCode == 2);
    CHECK(check.out.find("percent/case.json: /compare/failPercent: expected a number within [0, 100], got 200") !=
          std::string::npos);

    CHECK(runVfieldCli("golden check " + dir + "/no_such_folder --quiet", dir).exitCode == 2);
}

TEST_CASE("golden: a scene edited since its goldens were recorded fails its case and says so", "[golden]")
{
    const std::string dir = vfield::test::scratchDir("golden-scene-edited");
    fs::copy_file(vfield::test::dataPath("../../scenes/features/constant_density_box.json"), dir + "/shot.json");
    const vfield::test::CliRun record = runVfieldCli(
        "golden record " + dir + "/shot.json --frames 1 -o " + dir + "/case --resolution 64x36 --spp 1 --quiet", dir);
    REQUIRE(record.exitCode == 0);
    CHECK(runVfieldCli("golden check " + dir + "/case --quiet", dir).exitCode == 0);
    std::ofstream(dir + "/shot.json", std::ios::app) << "\n";
    const vfield::test::CliRun check = runVfieldCli("golden check " + dir + "/case --quiet", dir);
    CHECK(check.exitCode == 1);
    CHECK(check.out.find("shot.json changed since the goldens were made") != std::string::npos);
}

TEST_CASE("golden: density grids pass by their checksum, or within the tolerance of a kept golden grid", "[golden]")
{
    const std::string dir = vfield::test::scratchDir("golden-grids");
    const std::string box = recordBox(dir, "--keep-grids --grid-tolerance 0.001");
    nlohmann::json c = readCase(box);
    REQUIRE(c["grids"].size() == 1);
    const std::string recordedChecksum = c["grids"][0]["checksum"];
    CHECK(recordedChecksum == vfield::vdbFileChecksum(box + "/density.0001.vdb"));

    // Another checksum recorded (as another build's rounding would give): the kept grid decides.
    c["grids"][0]["checksum"] = "0000000000000000";
    writeCase(box, c);
    vfield::test::CliRun check = runVfieldCli("golden check " + box + " --quiet", dir);
    INFO(check.out);
    CHECK(check.exitCode == 0);

    // The kept grid 1% denser: its voxels differ by more than the tolerance.
    openvdb::GridPtrVec grids = vfield::readVdb(box + "/density.0001.vdb");
    for (const openvdb::GridBase::Ptr& grid : grids)
        if (auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(grid))
            for (auto v = density->beginValueOn(); v; ++v) v.setValue(*v * 1.01f + 0.002f);
    vfield::writeVdb(box + "/density.0001.vdb", grids);
    check = runVfieldCli("golden check " + box + " --quiet", dir);
    CHECK(check.exitCode == 1);
    CHECK(check.out.find("sim/density.0001.vdb: voxels differ") != std::string::npos);

    // Without a kept grid, only the checksum can decide.
    c["grids"][0]["keepFile"] = false;
    writeCase(box, c);
    check = runVfieldCli("golden check " + box + " --quiet", dir);
    CHECK(check.exitCode == 1);
    CHECK(check.out.find("sim/density.0001.vdb: checksum " + recordedChecksum + ", the golden's 0000000000000000") !=
          std::string::npos);
}
