#include <vfield/run/shard_part.h>

#include <vfield/core/error.h>
#include <vfield/core/hash.h>

#include <filesystem>

namespace vfield {

ShardPart ShardPart::parse(const std::string& text)
{
    if (text == "objects") return objects();
    const std::size_t slash = text.find('/');
    ShardPart part;
    try {
        std::size_t end = 0;
        part.index = std::stoi(text.substr(0, slash), &end);
        if (slash == std::string::npos || end != slash) throw std::invalid_argument(text);
        part.count = std::stoi(text.substr(slash + 1), &end);
        if (slash + 1 + end != text.size()) throw std::invalid_argument(text);
    } catch (const std::logic_error&) {
        throw ValueError("shard '" + text + "': expected objects or I/K, as 3/8");
    }
    if (part.count < 1 || part.index < 0 || part.index >= part.count) throw ValueError("shard '" + text + "': needs 0 <= I < K");
    return part;
}

std::string ShardPart::text() const { return isObjects() ? "objects" : std::to_string(index) + "/" + std::to_string(count); }

std::string ShardPart::folder(const std::string& out) const
{
    const std::string name = isObjects() ? "objects" : std::to_string(index) + "-of-" + std::to_string(count);
    return (std::filesystem::path(out) / "shards" / name).string();
}

uint64_t ShardPart::inputsHash(uint64_t simulation) const
{
    ContentHash hash;
    hash.addValue(simulation);
    hash.addValue(index);
    hash.addValue(count);
    return hash.value();
}

} // namespace vfield
