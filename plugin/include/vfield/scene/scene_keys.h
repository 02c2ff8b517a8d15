#pragma once
/// @file scene_keys.h
/// The documentation of every key a scene file may hold, derived from the
/// options structs' declarations (core/fields.h): a table per object of the
/// file ("scene", "objects[]", "objects[].mesh.terrain", ...). Documents
/// (docs/scenes.md) hold them between marker lines
///     <!-- keys: objects[] -->
///     | key | type | default | meaning |
///     ...
///     <!-- end keys -->
/// which `vfield help keys --update` rewrites and `--check` compares, so the
/// tables never drift from the code.

#include <vfield/core/field_visitors.h>

#include <string>
#include <vector>

namespace vfield {

/// Every table of a scene file's keys, the top level ("scene") first.
std::vector<FieldTable> sceneKeyTables();

/// A document with its key tables brought up to date.
struct KeyTableUpdate {
    std::string text;                 ///< the document with every marked table replaced by the current one
    std::vector<std::string> stale;   ///< titles of the tables that differed
    std::vector<std::string> unknown; ///< titles marked in the document that no table has
    std::vector<std::string> absent;  ///< tables the document does not hold
};
KeyTableUpdate updateKeyTables(const std::string& document, const std::vector<FieldTable>& tables);

} // namespace vfield
