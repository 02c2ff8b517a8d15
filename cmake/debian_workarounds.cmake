# Two of vfield's dependencies need working around as Debian 12 ships them,
# in vfield's own build and in every project that finds the installed vfield
# (vfieldConfig.cmake includes this file too).

# OpenVDB ships only a find module, in lib/<multiarch>/cmake/OpenVDB; that
# folder also holds a FindTBB.cmake, so find TBB by its config file
# (find_package(TBB 2021 CONFIG)) before OpenVDB.
list(APPEND CMAKE_MODULE_PATH "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB")

# OIIO's exported target names /usr/include/opencv4, which only libopencv-dev
# creates, and CMake refuses a target with a missing include directory; drop
# that entry rather than install OpenCV. Call it after finding OpenImageIO.
function(vfield_drop_opencv_include_of_openimageio)
  get_target_property(includes OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
  list(FILTER includes EXCLUDE REGEX "opencv4")
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${includes}")
endfunction()
