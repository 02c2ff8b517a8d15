#include "declared_flags.h"

namespace vfield::cli {

std::string flagName(const std::string& key)
{
    std::string name = "--";
    for (const char c : key) {
        if (std::isupper(static_cast<unsigned char>(c)))
            name += std::string("-") + char(std::tolower(static_cast<unsigned char>(c)));
        else name += c;
    }
    return name;
}

std::string DeclaredFlags::jsonObject(const nlohmann::json& base) const
{
    std::string text = "{";
    for (const auto& [key, value] : base.items())
        text += (text.size() > 1 ? ", " : "") + nlohmann::json(key).dump() + ": " + value.dump();
    for (const auto& [key, value] : mValues) text += (text.size() > 1 ? ", " : "") + nlohmann::json(key).dump() + ": " + value;
    return text + "}";
}

std::string DeclaredFlags::flagOf(const ParseError& error) const
{
    // what() is "command line: /key...: detail"; the flag stands for the key.
    const std::string& location = error.location();
    const std::size_t end = location.find('/', 1);
    const std::string key = location.substr(1, end == std::string::npos ? std::string::npos : end - 1);
    const std::string prefix = error.path() + ": " + location + ": ";
    const std::string what = error.what();
    const std::string detail = what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what;
    return (key.empty() ? std::string("command line") : flagName(key)) + ": " + detail;
}

} // namespace vfield::cli
