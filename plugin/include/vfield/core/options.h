#pragma once
/// @file options.h
/// The checks behind every options struct's validate(): each limit is stated
/// once, in the struct, and a failure names the option (OptionError) with the
/// same words a scene reader uses ("expected a number within [0, 1], got 2").

#include <vfield/core/error.h>

#include <cstdint>
#include <string>

namespace vfield {

/// Throws OptionError(key, "expected a number within [min, max], got value")
/// unless min <= value <= max (NaN never is).
void requireNumber(const std::string& key, double value, double min, double max);
/// Throws OptionError(key, "expected a positive integer, got value") style
/// errors unless min <= value <= max ("of at most max" when above it).
void requireInteger(const std::string& key, int64_t value, int64_t min, int64_t max);
/// Throws OptionError(key, detail) unless ok.
void require(bool ok, const std::string& key, const std::string& detail);
/// The same OptionError with its key under prefix ("carves/2" + "halfWidth").
[[noreturn]] void rethrowUnder(const std::string& prefix, const OptionError& error);
/// "1.5" style text of a number, as messages print it.
std::string numberText(double value);

/// Runs a nested struct's validate(), its failure's key placed under prefix.
template<typename Part>
void validatePart(const std::string& prefix, const Part& part)
{
    try {
        part.validate();
    } catch (const OptionError& error) {
        rethrowUnder(prefix, error);
    }
}

} // namespace vfield
