#pragma once
/// @file golden_case.h
/// A golden case: a folder holding case.json and, beside it, the goldens (the
/// images, and the OpenVDB grids it keeps, that a shot must keep making).
/// case.json says which vfield commands make the outputs, which outputs to
/// compare with the goldens, and how strictly:
///
///     {
///       "why": "what the case guards, and why its thresholds are what they are",
///       "scene": "../../scenes/shot.json",
///       "sceneHash": "0f3a...",
///       "commands": [["simulate", "@SCENE@", "-o", "@OUT@/sim", "--frames", "1-240"],
///                    ["render", "@SCENE@", "--sim", "@OUT@/sim", "-o", "@OUT@/images", "--frames", "240", ...]],
///       "images": ["images/frame.0240.png"],
///       "grids": [{"file": "sim/density.0240.vdb", "checksum": "...", "keepFile": true, "tolerance": 1e-05}],
///       "compare": {"fail": 0.004, "failPercent": 0.1, "hardFail": 0.05, "warn": 0.002, "warnPercent": 0.5,
///                   "diffScale": 10},
///       "regenerated": [{"date": "2026-11-26", "reason": "...", "differences": ["frame.0240.png: ..."]}]
///     }
///
/// "scene" is relative to the case folder, and "sceneHash" its content hash
/// (core/hash.h) when the goldens were made: a check whose scene changed fails
/// and says so. In "commands", @SCENE@ stands for the scene's path, @OUT@ for
/// the folder the case's outputs are written to, @CASE@ for the case folder.
/// "images" and "grids" name outputs relative to @OUT@; each one's golden is
/// the file of the same name beside case.json. A grid file passes when its
/// checksum (of every grid in it, whatever the file's random id) equals the
/// recorded one or, when its golden file is kept ("keepFile"), when every
/// voxel is within "tolerance" of that file's. "compare" holds `vfield compare`'s idiff thresholds.

#include <vfield/core/fields.h>
#include <vfield/image/image_compare.h>

#include <optional>
#include <string>
#include <vector>

namespace vfield {

struct GoldenGrid {
    std::string file; ///< e.g. "sim/density.0120.vdb"
    std::string checksum;
    bool keepFile = false; ///< to compare voxels when checksums differ
    double tolerance = 0.0;

    void validate() const;

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("file", self.file).required().doc("the grid file, relative to the outputs' folder"));
        visit(field("checksum", self.checksum).doc("vdbFileChecksum of the golden, 16 hex digits"));
        visit(field("keepFile", self.keepFile).doc("the golden file is kept beside case.json"));
        visit(field("tolerance", self.tolerance).atLeast(0).doc("largest voxel difference accepted against the kept file"));
    }
};

/// One time the goldens were remade on purpose.
struct GoldenRegeneration {
    std::string date, reason;
    std::vector<std::string> differences;

    void validate() const {}

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("date", self.date).required().doc("when, YYYY-MM-DD"));
        visit(field("reason", self.reason).required().doc("why the goldens changed"));
        visit(field("differences", self.differences).doc("per output, how the new one differed from the old"));
    }
};

/// How strictly a case's images are compared: `vfield compare`'s idiff
/// thresholds, as case.json's "compare" holds them.
struct GoldenThresholds {
    double fail = 1e-6;
    double failPercent = 0.0;
    std::optional<double> hardFail; ///< none: no limit
    double warn = 1e-6;
    double warnPercent = 0.0;
    double diffScale = 10.0;

    void validate() const;
    ImageCompareOptions imageCompareOptions() const;
    static GoldenThresholds from(const ImageCompareOptions& options);

    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("fail", self.fail).atLeast(0).doc("a pixel fails when a channel differs by more"));
        visit(field("failPercent", self.failPercent).range(0, 100).doc("% of pixels allowed to fail"));
        visit(field("hardFail", self.hardFail).atLeast(0).doc("fail when any channel differs by more"));
        visit(field("warn", self.warn).atLeast(0).doc("a pixel warns when a channel differs by more"));
        visit(field("warnPercent", self.warnPercent).range(0, 100).doc("% of pixels allowed to warn"));
        visit(field("diffScale", self.diffScale).range(1e-9, 1e9).doc("difference images show |golden - new| times this"));
    }
};

struct GoldenCase {
    std::string folder; ///< where case.json is (absolute); not in the file
    std::string why;
    std::string scene; ///< empty when the commands read no scene
    std::string sceneHash;
    std::vector<std::vector<std::string>> commands;
    std::vector<std::string> images;
    std::vector<GoldenGrid> grids;
    GoldenThresholds compare;
    std::vector<GoldenRegeneration> regenerated;

    std::string caseFile() const { return folder + "/case.json"; }
    /// The scene's path as the commands see it (empty when there is none).
    std::string scenePath() const;
    /// The golden of an output: the file of its name beside case.json.
    std::string goldenPath(const std::string& output) const;
    /// The commands with @SCENE@, @OUT@ and @CASE@ replaced.
    std::vector<std::vector<std::string>> commandsFor(const std::string& outDir) const;

    /// Throws OptionError naming an empty command line.
    void validate() const;

    /// case.json's keys.
    template<typename Self, typename Visitor>
    static void visitFields(Self& self, Visitor& visit)
    {
        visit(field("why", self.why).doc("what the case guards, and why its thresholds are what they are"));
        visit(field("scene", self.scene).doc("the scene, relative to the case folder"));
        visit(field("sceneHash", self.sceneHash).doc("the scene's content hash when the goldens were made"));
        visit(field("commands", self.commands)
                  .required()
                  .doc("vfield command lines; @SCENE@, @OUT@ and @CASE@ stand for the scene, the outputs' folder and the "
                       "case folder"));
        visit(field("images", self.images).required().doc("images compared with their goldens, relative to @OUT@"));
        visit(field("grids", self.grids).doc("grid files compared with their goldens"));
        visit(field("compare", self.compare).required().doc("the images' idiff thresholds"));
        visit(field("regenerated", self.regenerated).doc("each time the goldens were remade on purpose"));
    }
};

/// Reads folder/case.json. Throws FileError, or ParseError at the JSON path.
GoldenCase readGoldenCase(const std::string& folder);
/// Writes c.caseFile() (atomically).
void writeGoldenCase(const GoldenCase& c);

/// A case found under a folder, named by its path relative to that folder.
struct GoldenCaseRef {
    std::string name, folder;
};
/// The case at root (named after its folder) or, when root holds no
/// case.json, every case below it, sorted by name. Throws FileError when root
/// does not exist or holds no case.
std::vector<GoldenCaseRef> findGoldenCases(const std::string& root);

/// The content hash of a file's bytes, as 16 hex digits.
std::string fileContentHash(const std::string& path);
/// The checksum of every grid of an OpenVDB file in turn (gridChecksum), as
/// 16 hex digits: equal for equal contents whatever the file's random id.
std::string vdbFileChecksum(const std::string& path);

} // namespace vfield
