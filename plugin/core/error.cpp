#include <vfield/core/error.h>

namespace vfield {

FileError::FileError(const std::string& path, const std::string& message) : Error(path + ": " + message), mPath(path) {}

ParseError::ParseError(const std::string& path, const std::string& location, const std::string& message)
    : FileError(path, location + ": " + message), mLocation(location)
{}

OptionError::OptionError(const std::string& key, const std::string& detail)
    : ValueError(key.empty() ? detail : key + ": " + detail), mKey(key), mDetail(detail)
{}

} // namespace vfield
