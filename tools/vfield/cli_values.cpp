#include "cli_values.h"

#include <vfield/core/error.h>

#include <cctype>
#include <cmath>
#include <sstream>

namespace vfield::cli {

namespace {

/// The value of text if it is an integer and nothing else.
std::optional<int> wholeInteger(const std::string& text)
{
    std::istringstream in(text);
    int value = 0;
    if (!(in >> value) || !in.eof()) return std::nullopt;
    return value;
}

} // namespace

void addFrameRangeOption(CLI::App& command, std::optional<FrameRange>& range, const std::string& help)
{
    command
        .add_option_function<std::string>(
            "--frames",
            [&range](const std::string& text) {
                const std::size_t dash = text.find('-', 1);
                const std::optional<int> first = wholeInteger(text.substr(0, dash));
                const std::optional<int> last = dash == std::string::npos ? first : wholeInteger(text.substr(dash + 1));
                if (!first || !last) throw CLI::ValidationError("--frames", "expected A-B or A, got '" + text + "'");
                if (*last < *first) throw CLI::ValidationError("--frames", "the range " + text + " ends before it starts");
                range = FrameRange{*first, *last};
            },
            help)
        ->type_name("A-B");
}

void addMaxMemoryOption(CLI::App& command, std::optional<double>& bytes)
{
    command
        .add_option_function<std::string>(
            "--max-memory",
            [&bytes](const std::string& text) {
                std::istringstream in(text);
                double value = 0.0;
                std::string unit;
                const bool number = bool(in >> value);
                in >> unit;
                const std::string units = "KMGT";
                const std::size_t prefix =
                    unit.empty() ? std::string::npos : units.find(char(std::toupper(static_cast<unsigned char>(unit[0]))));
                const std::size_t power = unit.empty() ? 0 : prefix + 1;
                const bool known = unit.empty() || (prefix != std::string::npos &&
                                                    (unit.size() == 1 || unit.substr(1) == "iB" || unit.substr(1) == "B"));
                if (!number || !in.eof() || !(value > 0.0) || !known)
                    throw CLI::ValidationError("--max-memory", "expected a size such as 16G or 512M, got '" + text + "'");
                bytes = value * std::pow(1024.0, double(power));
            },
            "Refuse a scene or mesh estimated to need more memory than this, before loading it "
            "(docs/simulation.md, \"Memory\") [default: the memory available]")
        ->type_name("SIZE");
}

void addWaitOption(CLI::App& command, bool& wait)
{
    command.add_flag("--wait", wait,
                     "When another vfield is writing the output folder, wait for it to finish instead of refusing "
                     "(a farm's jobs, a requeued job)");
}

FolderLock::Waiting folderWaiting(bool wait, const GlobalOptions& global, const std::string& folder)
{
    if (!wait) return {};
    return [&global, folder](const std::string& holder) { log(global, folder + ": waiting for " + holder); };
}

} // namespace vfield::cli
