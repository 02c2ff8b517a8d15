#pragma once
// Values that several subcommands take, each parsed once while the command
// line is parsed (a bad one is a usage error, exit 2) into typed options.

#include "command.h"

#include <vfield/core/folder_lock.h>

#include <optional>

namespace vfield::cli {

struct FrameRange {
    int first = 0, last = 0;
};

/// --frames A-B or A.
void addFrameRangeOption(CLI::App& command, std::optional<FrameRange>& range, const std::string& help);

/// --wait: wait for another vfield writing the same folder instead of
/// refusing; the returned waiting callback logs who (empty without --wait).
void addWaitOption(CLI::App& command, bool& wait);
FolderLock::Waiting folderWaiting(bool wait, const GlobalOptions& global, const std::string& folder);

/// --max-memory SIZE (bytes, or with K, M, G, T: binary multiples) for the commands that simulate.
void addMaxMemoryOption(CLI::App& command, std::optional<double>& bytes);

} // namespace vfield::cli
