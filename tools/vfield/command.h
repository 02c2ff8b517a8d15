#pragma once
// The shape every subcommand file follows: it declares its options on a CLI11
// subcommand and returns the function that runs it once parsing succeeded.

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>

namespace vfield::cli {

/// Options every subcommand shares.
struct GlobalOptions {
    bool quiet = false; ///< no progress or log lines on stderr
};

/// Runs a parsed subcommand; throws vfield::Error (or std::exception) on failure.
using Runner = std::function<void()>;

Runner registerMakeMesh(CLI::App& app, const GlobalOptions& global);
Runner registerProbe(CLI::App& app, const GlobalOptions& global);
Runner registerBakeField(CLI::App& app, const GlobalOptions& global);
Runner registerFieldSlice(CLI::App& app, const GlobalOptions& global);
Runner registerInfo(CLI::App& app, const GlobalOptions& global);
Runner registerSimulate(CLI::App& app, const GlobalOptions& global);
Runner registerExportMesh(CLI::App& app, const GlobalOptions& global);
Runner registerExportScene(CLI::App& app, const GlobalOptions& global);
Runner registerRender(CLI::App& app, const GlobalOptions& global);
Runner registerRun(CLI::App& app, const GlobalOptions& global);
Runner registerCompare(CLI::App& app, const GlobalOptions& global);
Runner registerMetrics(CLI::App& app, const GlobalOptions& global);
Runner registerFarm(CLI::App& app, const GlobalOptions& global);
Runner registerHelp(CLI::App& app, const GlobalOptions& global);
Runner registerVerify(CLI::App& app, const GlobalOptions& global);
Runner registerSilhouette(CLI::App& app, const GlobalOptions& global);
Runner registerGolden(CLI::App& app, const GlobalOptions& global);

/// Thrown by a runner to end with an exit status other than 0 (success) and 1
/// (an exception, its message reported): `vfield compare` exits 1 when the
/// inputs differ and 2 on errors, as idiff does. A non-empty message is
/// reported as errors are.
struct CommandExit {
    int status = 1;
    std::string message;
};

/// A log line on stderr, unless --quiet.
void log(const GlobalOptions& global, const std::string& line);

/// Limits TBB to `threads` workers while the returned object lives; 0: no limit.
std::shared_ptr<void> limitThreads(int threads);

} // namespace vfield::cli
