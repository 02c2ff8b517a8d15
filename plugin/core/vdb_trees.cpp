// The one instantiation of the grid and tree classes vdb_trees.h declares.
#include <vfield/core/vdb_trees.h>

template class openvdb::tree::Tree<openvdb::FloatTree::RootNodeType>;
template class openvdb::tree::Tree<openvdb::Vec3STree::RootNodeType>;
template class openvdb::tree::Tree<openvdb::MaskTree::RootNodeType>;
template class openvdb::Grid<openvdb::FloatTree>;
template class openvdb::Grid<openvdb::Vec3STree>;
template class openvdb::Grid<openvdb::MaskTree>;
