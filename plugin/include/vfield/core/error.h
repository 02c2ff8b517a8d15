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

/// An option of an options struct is out of range (thrown by the structs'
/// validate()). key() names it as a scene file does, as a path below the
/// struct when it is nested ("surfaceBoost", "cells/0", "clouds/2/count"), so a
/// scene reader reports it at its JSON path (see validateAt in json.h).
/// An empty key names the struct itself. what() = "<key>: <detail>".
class OptionError : public ValueError {
public:
    OptionError(const std::string& key, const std::string& detail);
    const std::string& key() const { return mKey; }
    const std::string& detail() const { return mDetail; } ///< e.g. "expected a number within [1, 1e+12], got 0.5"

private:
    std::string mKey, mDetail;
};

} // namespace vfield
