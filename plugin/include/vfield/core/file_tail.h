#pragma once
/// @file file_tail.h
/// The end of a file another process may still be writing (a child's log):
/// where its newest progress line is, read without reading the rest.

#include <cstddef>
#include <string>

namespace vfield {

/// The file's last maxBytes bytes (all of it when shorter); "" when it cannot be read.
std::string fileTail(const std::string& path, std::size_t maxBytes);

} // namespace vfield
