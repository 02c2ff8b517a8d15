#include "child_process.h"

#include <vfield/core/error.h>
#include <vfield/core/file_tail.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;

namespace vfield::cli {

std::string lastLogLine(const std::string& logPath)
{
    std::string tail = fileTail(logPath, 4096);
    while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
    const std::size_t from = tail.find_last_of("\r\n");
    return from == std::string::npos ? tail : tail.substr(from + 1);
}

int runVfield(const std::vector<std::string>& arguments, const std::string& logPath,
              const std::function<void(const std::string& line)>& onLine)
{
    const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(self.c_str()));
    for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, logPath.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t child = 0;
    const int error = posix_spawn(&child, self.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (error != 0) throw Error("cannot run " + self + ": " + std::strerror(error));

    std::string shown;
    for (;;) {
        int status = 0;
        const pid_t done = ::waitpid(child, &status, WNOHANG);
        if (done == child) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        if (done < 0 && errno != EINTR) throw Error(std::string("waiting for vfield: ") + std::strerror(errno));
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        const std::string line = lastLogLine(logPath);
        if (!line.empty() && line != shown) onLine(shown = line);
    }
}

} // namespace vfield::cli
