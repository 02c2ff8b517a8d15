#pragma once
/// @file atomic_file.h
/// Files as vfield writes and reads them. Every file vfield writes appears
/// whole or not at all: it is written under a temporary name beside its
/// destination and renamed into place, so an interrupted run never leaves a
/// half-written output.

#include <functional>
#include <string>

namespace vfield {

/// Calls write(temporaryPath) to produce the file, then renames it to path.
/// The temporary lies in the same folder (rename is atomic there) and keeps the
/// extension, so writers that choose a format by extension still work. If write
/// throws, the temporary is removed and the exception propagates; path is untouched.
/// Missing parent folders are created.
void writeFileAtomically(const std::string& path, const std::function<void(const std::string& temporaryPath)>& write);

/// Writes text to path atomically.
void writeTextAtomically(const std::string& path, const std::string& text);

/// The whole file's bytes. Throws FileError naming it: "no such file" or
/// "cannot open for reading".
std::string readFileBytes(const std::string& path);

} // namespace vfield
