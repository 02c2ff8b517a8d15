#include <vfield/core/options.h>

#include <cmath>
#include <sstream>

namespace vfield {

std::string numberText(double value)
{
    std::ostringstream text;
    text << value;
    return text.str();
}

void requireNumber(const std::string& key, double value, double min, double max)
{
    if (value >= min && value <= max) return;
    const std::string expected = std::isinf(max)   ? ">= " + numberText(min)
                                 : std::isinf(min) ? "<= " + numberText(max)
                                                   : "within [" + numberText(min) + ", " + numberText(max) + "]";
    throw OptionError(key, "expected a number " + expected + ", got " + numberText(value));
}

void requireInteger(const std::string& key, int64_t value, int64_t min, int64_t max)
{
    const std::string kind = min == 1 ? "a positive integer" : min == 0 ? "a non-negative integer" : "an integer";
    if (value < min) throw OptionError(key, "expected " + kind + ", got " + std::to_string(value));
    if (value > max)
        throw OptionError(key, "expected " + kind + " of at most " + std::to_string(max) + ", got " + std::to_string(value));
}

void require(bool ok, const std::string& key, const std::string& detail)
{
    if (!ok) throw OptionError(key, detail);
}

void rethrowUnder(const std::string& prefix, const OptionError& error)
{
    throw OptionError(error.key().empty() ? prefix : prefix + "/" + error.key(), error.detail());
}

} // namespace vfield
