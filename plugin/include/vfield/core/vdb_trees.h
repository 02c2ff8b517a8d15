#pragma once
/// @file vdb_trees.h
/// OpenVDB, as vfield's headers include it: with the grid and tree classes
/// vfield uses declared instantiated elsewhere, once, in libvfield
/// (core/vdb_trees.cpp). A grid's virtual functions (voxel counts, memory
/// use, I/O, topology) pull in most of its tree's code, which every file
/// that touches the grid would otherwise compile again; libopenvdb
/// instantiates its tools this way but not its trees.

#include <openvdb/openvdb.h>

extern template class openvdb::tree::Tree<openvdb::FloatTree::RootNodeType>;
extern template class openvdb::tree::Tree<openvdb::Vec3STree::RootNodeType>;
extern template class openvdb::tree::Tree<openvdb::MaskTree::RootNodeType>;
extern template class openvdb::Grid<openvdb::FloatTree>;
extern template class openvdb::Grid<openvdb::Vec3STree>;
extern template class openvdb::Grid<openvdb::MaskTree>;
