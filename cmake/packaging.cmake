# How other projects use the installed vfield: the CMake package
# (find_package(vfield) -> vfield::vfield), its version file, the pkg-config
# file vfield.pc; and the Debian package tools/package makes with CPack.
include(CMakePackageConfigHelpers)

set(package_dir ${CMAKE_INSTALL_LIBDIR}/cmake/vfield)
install(EXPORT vfieldTargets NAMESPACE vfield:: DESTINATION ${package_dir})
configure_package_config_file(cmake/vfieldConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/vfieldConfig.cmake
  INSTALL_DESTINATION ${package_dir})
# The library's soname changes with the major version, and so may its API.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/vfieldConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/vfieldConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/vfieldConfigVersion.cmake
  cmake/debian_workarounds.cmake DESTINATION ${package_dir})

# OpenVDB has no pkg-config file of its own: its compile definitions (the ABI
# its headers must match) come from its find module's target.
get_target_property(openvdb_definitions OpenVDB::openvdb INTERFACE_COMPILE_DEFINITIONS)
list(TRANSFORM openvdb_definitions PREPEND "-D")
list(JOIN openvdb_definitions " " openvdb_cflags)
file(RELATIVE_PATH prefix_from_pcfiledir "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
configure_file(cmake/vfield.pc.in ${CMAKE_CURRENT_BINARY_DIR}/vfield.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/vfield.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# One package, vfield, holding the command, the library and what building
# against it takes; Depends names the Debian 12 packages of the libraries it
# links (libvfield's and vfield's NEEDED entries) and of the programs it runs
# (POV-Ray; oiiotool, ffmpeg and the DejaVu font for make-sheet), as
# tools/setup installs them. Building against it also takes the -dev packages.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Collision-free motion through octree vector fields, voxelized into OpenVDB")
set(CPACK_PACKAGE_DESCRIPTION
  "vfield wraps every mesh in a repulsive octree vector field (Egbert & Winkler), moves particle clouds and rigid meshes \
through the sum of the fields without collisions, writes OpenVDB volumes and particles per frame and renders them with \
Embree or POV-Ray. This package holds the vfield command, libvfield with its headers, CMake package and pkg-config \
file, and the Blender add-on's zip.")
set(CPACK_PACKAGE_CONTACT "vfield maintainers <maintainers@users.noreply.h-seed-b9ecf6ab.example>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
# A shlibs file for libvfield.so.0, and the ldconfig trigger that comes with it.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
  "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, libopenvdb10.0, libembree3-3, libopenimageio2.4, libimath-3-1-29, libtbb12, libassimp5, povray, openimageio-tools, ffmpeg, fonts-dejavu-core")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
  "libopenvdb-dev, libboost-iostreams-dev, libopenimageio-dev, libtbb-dev, nlohmann-json3-dev, blender, slurm-wlm")
include(CPack)
