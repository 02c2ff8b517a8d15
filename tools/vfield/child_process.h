#pragma once
// Runs this vfield binary again as a child process, with its stderr in a log
// file, and reports the log's last line while it runs (the child's progress).

#include <functional>
#include <string>
#include <vector>

namespace vfield::cli {

/// Runs `vfield arguments...` (this very binary), stdout and stderr appended to
/// logPath; calls onLine with the log's newest line whenever it changes (about
/// every 0.2 s). Returns the exit status (128 + the signal when killed).
int runVfield(const std::vector<std::string>& arguments, const std::string& logPath,
              const std::function<void(const std::string& line)>& onLine);

/// The log's last non-empty line (for an error message), or "".
std::string lastLogLine(const std::string& logPath);

} // namespace vfield::cli
