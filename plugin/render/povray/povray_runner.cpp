#include <vfield/render/povray/povray_runner.h>

#include <vfield/core/error.h>
#include <vfield/core/file_tail.h>
#include <vfield/core/stopwatch.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace vfield {

namespace {

const char* const kProgram = "povray";

/// The last few non-empty lines of POV-Ray's log, joined into one line.
std::string logTail(const std::string& logPath, std::size_t lines = 4)
{
    std::ifstream in(logPath);
    std::deque<std::string> tail;
    for (std::string line; std::getline(in, line);) {
        line.erase(line.find_last_not_of(" \t\r") + 1);
        line.erase(0, line.find_last_of('\r') + 1); // of progress lines rewritten in place, the last
        if (line.empty()) continue;
        tail.push_back(line);
        if (tail.size() > lines) tail.pop_front();
    }
    std::string joined;
    for (const std::string& line : tail) joined += (joined.empty() ? "" : " | ") + line;
    return joined.empty() ? "(no output)" : joined;
}

/// The fraction of pixels POV-Ray's newest "Rendered A of B pixels" line in
/// its log reports, or -1.
double renderedFraction(const std::string& logPath)
{
    const std::string tail = fileTail(logPath, 256);
    const std::size_t at = tail.rfind("Rendered ");
    unsigned long long done = 0, total = 0;
    if (at == std::string::npos || std::sscanf(tail.c_str() + at, "Rendered %llu of %llu", &done, &total) != 2 || total == 0)
        return -1.0;
    return double(done) / double(total);
}

} // namespace

bool povrayAvailable()
{
    const char* path = std::getenv("PATH");
    std::istringstream folders(path ? path : "");
    for (std::string folder; std::getline(folders, folder, ':');) {
        const fs::path candidate = fs::path(folder.empty() ? "." : folder) / kProgram;
        if (::access(candidate.c_str(), X_OK) == 0) return true;
    }
    return false;
}

void requirePovray()
{
    if (!povrayAvailable())
        throw Error("POV-Ray (the povray program) is not on PATH; install the Debian package 'povray' (tools/setup does)");
}

std::optional<std::string> povrayVersion()
{
    if (!povrayAvailable()) return std::nullopt;
    // `povray --version` prints its banner, "POV-Ray 3.7.0.10.unofficial" first,
    // after a complaint when the user has no povray.conf of their own.
    std::FILE* pipe = ::popen((std::string(kProgram) + " --version 2>&1 </dev/null").c_str(), "r");
    if (!pipe) return std::nullopt;
    std::optional<std::string> version;
    const std::string banner = "POV-Ray ";
    for (char line[256]; std::fgets(line, sizeof line, pipe);) {
        const std::string text(line);
        if (!version && text.rfind(banner, 0) == 0)
            version = text.substr(banner.size(), text.find_first_of(" \r\n", banner.size()) - banner.size());
    }
    ::pclose(pipe);
    return version;
}

void runPovray(const std::string& folder, const std::string& sceneFile, const std::string& imageFile, const ImageSettings& image,
               PovrayQuality quality, int threads, const std::function<void(double fraction)>& progress)
{
    requirePovray();
    image.validate();
    if (threads < 1) throw ValueError("POV-Ray needs at least one thread");

    std::vector<std::string> args = {kProgram,
                                     "+I" + sceneFile,
                                     "+O" + imageFile,
                                     "+W" + std::to_string(image.width),
                                     "+H" + std::to_string(image.height),
                                     "+WT" + std::to_string(threads),
                                     "-D",   // no display
                                     "+V",   // progress lines ("Rendered 1024 of 76800 pixels"), read below
                                     "-P",   // no pause
                                     "+FE"}; // OpenEXR: scene-linear, as vfield's own frames before the view
    const int grid = std::clamp(int(std::lround(std::sqrt(double(image.samplesPerPixel)))), 1, 9);
    if (quality == PovrayQuality::Preview && image.samplesPerPixel > 1) {
        // Supersampled 2 x 2 only where a pixel stands out from its neighbours.
        for (const char* a : {"+A0.3", "+AM1", "+R2", "-J"}) args.push_back(a);
    } else if (grid > 1) {
        // Supersampled on an unjittered n x n grid: every pixel at threshold
        // 0, else those that POV-Ray finds differ from a neighbour by more
        // than adaptiveThreshold (its own measure of the difference). Its
        // parser wants a decimal point ("+A0" fails): std::to_string's six places.
        for (const std::string& a : {"+A" + std::to_string(image.adaptiveThreshold), std::string("+AM1"),
                                     "+R" + std::to_string(grid), std::string("-J")})
            args.push_back(a);
    } else {
        args.push_back("-A");
    }
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    const std::string logPath = (fs::path(folder) / (imageFile + ".log")).string();
    const pid_t child = ::fork();
    if (child < 0) throw Error(std::string("cannot start POV-Ray: ") + std::strerror(errno));
    if (child == 0) {
        // In the child only async-signal-safe calls until exec.
        const int log = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int devNull = ::open("/dev/null", O_RDONLY);
        if (log < 0 || devNull < 0 || ::chdir(folder.c_str()) != 0) ::_exit(126);
        ::dup2(devNull, 0);
        ::dup2(log, 1);
        ::dup2(log, 2);
        ::execvp(kProgram, argv.data());
        ::_exit(127);
    }
    // POV-Ray reports a block of pixels when it is done; with media and
    // supersampling that can take many seconds, so the fraction is told again
    // every second, grown or not.
    int status = 0;
    double reported = -1.0;
    Stopwatch sinceTold;
    for (;;) {
        const pid_t done = ::waitpid(child, &status, WNOHANG);
        if (done == child) break;
        if (done < 0 && errno != EINTR) throw Error(std::string("lost POV-Ray: ") + std::strerror(errno));
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        const double fraction = std::max(0.0, renderedFraction(logPath));
        if (progress && (fraction > reported || sinceTold.seconds() >= 1.0)) {
            progress(reported = fraction);
            sinceTold.lap();
        }
    }
    const std::string scenePath = (fs::path(folder) / sceneFile).string();
    if (WIFSIGNALED(status))
        throw FileError(scenePath, "POV-Ray was killed by signal " + std::to_string(WTERMSIG(status)) + ": " + logTail(logPath) +
                                       " (log: " + logPath + ")");
    const int code = WEXITSTATUS(status);
    if (code == 126) throw FileError(folder, "cannot run POV-Ray here (its log or the folder cannot be opened)");
    if (code == 127) throw Error("POV-Ray (povray) could not be started; install the Debian package 'povray'");
    if (code != 0 || !fs::exists(fs::path(folder) / imageFile))
        throw FileError(scenePath, "POV-Ray failed (exit status " + std::to_string(code) + "): " + logTail(logPath) +
                                       " (log: " + logPath + ")");
}

} // namespace vfield
