# Fails when a stage of libvfield includes a stage after it. Data flows one
# way: core -> mesh -> field -> sim -> volume -> render -> image, and what
# composes them: the scene format (scene), the simulation folder's files
# (folder), what hosts use (host), the runs that make a folder and its images
# (run), and golden-image cases (golden).
# render/embree and render/povray are two rooms at one level after render:
# each may include render's shared files, never the other room. Run as
#   cmake -DPLUGIN_DIR=<plugin> -P check_layering.cmake
# Each stage with its level; a file may include its own stage and lower levels.
set(stages core:0 mesh:1 field:2 sim:3 volume:4 render:5 render/embree:6 render/povray:6 image:7 scene:8 folder:9 host:10 run:11 golden:12)

foreach(entry ${stages})
  string(REPLACE ":" ";" pair "${entry}")
  list(GET pair 0 name)
  list(GET pair 1 level)
  set(level_of_${name} ${level})
endforeach()

set(violations "")
foreach(entry ${stages})
  string(REPLACE ":" ";" pair "${entry}")
  list(GET pair 0 stage)
  # The stage's own files only: a room's files are not its parent's.
  file(GLOB files "${PLUGIN_DIR}/${stage}/*.cpp" "${PLUGIN_DIR}/${stage}/*.h" "${PLUGIN_DIR}/include/vfield/${stage}/*.h")
  foreach(file ${files})
    file(STRINGS "${file}" includes REGEX "#include <vfield/")
    foreach(line ${includes})
      if(line MATCHES "<vfield/(render/embree|render/povray)/")
        set(included "${CMAKE_MATCH_1}")
      elseif(line MATCHES "<vfield/([a-z_]+)/")
        set(included "${CMAKE_MATCH_1}")
      else()
        continue()
      endif()
      if(NOT DEFINED level_of_${included})
        list(APPEND violations "${file}: includes an unknown stage '${included}'")
      elseif(NOT included STREQUAL stage AND NOT level_of_${included} LESS level_of_${stage})
        list(APPEND violations "${file}: stage '${stage}' includes '${included}', which is not an earlier stage")
      endif()
    endforeach()
  endforeach()
endforeach()

if(violations)
  list(JOIN violations "\n" message)
  message(FATAL_ERROR "${message}")
endif()
message(STATUS "stages include only earlier stages")
