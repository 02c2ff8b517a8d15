#pragma once
/// @file field_visitors.h
/// What is derived from an options struct's one declaration of its fields
/// (fields.h):
///   readFields<T>(json, baseDir)  a scene file's object -> T, kinds checked,
///                                 unknown keys refused (ranges: validate())
///   checkFields(value)            every declared range, nested structs' validate()
///   hashFields(hash, value)       every field into a content hash
///   fieldsToJson(value)           the struct as a scene file writes it
///   describeFields<T>()           the documentation tables (`vfield help keys`)
///   atFrame(value, frame)         keyed members at one frame (animation.h)
/// Include this in .cpp files only: it brings nlohmann's JSON with it.

#include <vfield/core/field_animator.h>
#include <vfield/core/field_docs.h>
#include <vfield/core/field_hasher.h>
#include <vfield/core/field_reader.h>
#include <vfield/core/field_traits.h>
#include <vfield/core/field_writer.h>
