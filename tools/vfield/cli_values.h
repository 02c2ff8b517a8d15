#pragma once
// Values that several subcommands take, each parsed once while the command
// line is parsed (a bad one is a usage error, exit 2) into typed options.

#include "command.h"

#include <optional>

namespace vfield::cli {

struct FrameRange {
    int first = 0, last = 0;
};

/// --frames A-B or A.
void addFrameRangeOption(CLI::App& command, std::optional<FrameRange>& range, const std::string& help);

/// --max-memory SIZE (bytes, or with K, M, G, T: binary multiples) for the commands that simulate.
void addMaxMemoryOption(CLI::App& command, std::optional<double>& bytes);

} // namespace vfield::cli
