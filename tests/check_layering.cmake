# Fails when a stage of libvfield includes a stage after it. Data flows one
# way: core -> mesh -> field -> sim -> volume -> render -> image -> scene
# (scene composes the stages for the command line and the plugin API). Run as
#   cmake -DPLUGIN_DIR=<plugin> -P check_layering.cmake
set(stages core mesh field sim volume render image scene)

set(violations "")
list(LENGTH stages stage_count)
math(EXPR last "${stage_count} - 1")
foreach(i RANGE ${last})
  list(GET stages ${i} stage)
  file(GLOB_RECURSE files "${PLUGIN_DIR}/${stage}/*" "${PLUGIN_DIR}/include/vfield/${stage}/*")
  foreach(file ${files})
    file(STRINGS "${file}" includes REGEX "#include <vfield/")
    foreach(line ${includes})
      string(REGEX REPLACE ".*<vfield/([a-z_]+)/.*" "\\1" included "${line}")
      list(FIND stages "${included}" j)
      if(j GREATER i)
        list(APPEND violations "${file}: stage '${stage}' includes later stage '${included}'")
      endif()
    endforeach()
  endforeach()
endforeach()

if(violations)
  list(JOIN violations "\n" message)
  message(FATAL_ERROR "${message}")
endif()
message(STATUS "stages include only earlier stages")
