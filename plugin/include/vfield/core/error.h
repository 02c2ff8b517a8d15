#pragma once
/// @file error.h
/// The exceptions libvfield throws. The library never prints or exits: every
/// failure reaches the caller as one of these, whose what() is a single line
/// naming the file and the place ("terrain.ply: line 3: ..."), ready for stderr.

#include <stdexcept>
#include <string>

namespace vfield {

/// Base of every vfield exception.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A file could not be opened, read, understood or written.
/// what() = "<path>: <message>".
class FileError : public Error {
public:
    FileError(const std::string& path, const std::string& message);
    const std::string& path() const { return mPath; }

private:
    std::string mPath;
};

/// A text input is malformed at a known place: a JSON path ("/clouds/0/count")
/// or a "line L, column C". what() = "<path>: <location>: <message>".
class ParseError : public FileError {
public:
    ParseError(const std::string& path, const std::string& location, const std::string& message);
    const std::string& location() const { return mLocation; }

private:
    std::string mLocation;
};

/// An argument or option is out of its documented range.
class ValueError : public Error {
public:
    explicit ValueError(const std::string& message) : Error(message) {}
};

} // namespace vfield
