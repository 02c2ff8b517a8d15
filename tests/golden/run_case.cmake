# Runs one golden-image case and compares its images with the goldens.
#
#   cmake -DVFIELD=<vfield binary> -DCASE=<renders/golden/.../case.json>
#         -DSOURCE=<source tree> -DOUT=<scratch folder> [-DUPDATE=ON]
#         -P run_case.cmake
#
# A case file (JSON) holds:
#   "why":      what the case guards and why its thresholds are what they are
#   "regenerated": (optional, not read) each time its goldens were remade on
#               purpose (tools/update-goldens), when and why
#   "commands": vfield command lines (arrays of arguments); @SOURCE@ is the
#               source tree, @OUT@ the case's scratch folder
#   "images":   the images the commands write, relative to @OUT@; each is
#               compared with the file of the same name beside case.json
#   "compare":  the `vfield compare` thresholds (arguments)
# With UPDATE=ON the new images replace the goldens (tools/update-goldens),
# after reporting how they differ from the old ones.
cmake_minimum_required(VERSION 3.21)

foreach(required VFIELD CASE SOURCE OUT)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "run_case.cmake needs -D${required}=...")
  endif()
endforeach()
file(READ "${CASE}" case_json)
get_filename_component(golden_dir "${CASE}" DIRECTORY)

# The elements of a JSON array of strings, as a CMake list.
function(json_strings out json)
  set(items "")
  string(JSON count LENGTH "${json}")
  if(count GREATER 0)
    math(EXPR last "${count} - 1")
    foreach(i RANGE ${last})
      string(JSON item GET "${json}" ${i})
      string(REPLACE "@SOURCE@" "${SOURCE}" item "${item}")
      string(REPLACE "@OUT@" "${OUT}" item "${item}")
      list(APPEND items "${item}")
    endforeach()
  endif()
  set(${out} "${items}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")

string(JSON commands GET "${case_json}" commands)
string(JSON command_count LENGTH "${commands}")
math(EXPR last_command "${command_count} - 1")
foreach(i RANGE ${last_command})
  string(JSON command GET "${commands}" ${i})
  json_strings(arguments "${command}")
  execute_process(COMMAND "${VFIELD}" ${arguments} --quiet RESULT_VARIABLE status ERROR_VARIABLE errors OUTPUT_QUIET)
  if(NOT status EQUAL 0)
    list(JOIN arguments " " line)
    message(FATAL_ERROR "golden case ${CASE}: `vfield ${line}` failed (${status}): ${errors}")
  endif()
endforeach()

string(JSON thresholds GET "${case_json}" compare)
json_strings(compare_arguments "${thresholds}")
string(JSON images GET "${case_json}" images)
json_strings(image_list "${images}")
set(failures "")
foreach(image ${image_list})
  get_filename_component(name "${image}" NAME)
  get_filename_component(stem "${image}" NAME_WLE)
  set(new "${OUT}/${image}")
  set(golden "${golden_dir}/${name}")
  set(diff "${OUT}/${stem}.diff.png")
  if(NOT EXISTS "${golden}")
    if(UPDATE)
      file(COPY_FILE "${new}" "${golden}")
      message(STATUS "${golden}: new golden")
      continue()
    endif()
    list(APPEND failures "${golden}: no such golden (tools/update-goldens makes it)")
    continue()
  endif()
  execute_process(COMMAND "${VFIELD}" compare "${golden}" "${new}" ${compare_arguments} --diff "${diff}"
                  RESULT_VARIABLE status OUTPUT_VARIABLE report ERROR_VARIABLE errors)
  if(UPDATE)
    message(STATUS "${golden} -> new image:\n${report}${errors}")
    file(COPY_FILE "${new}" "${golden}")
  elseif(NOT status EQUAL 0)
    list(APPEND failures "${golden}: differs from the new image ${new} (difference x10: ${diff})\n${report}${errors}")
  else()
    message(STATUS "${name}:\n${report}")
  endif()
endforeach()

if(failures)
  list(JOIN failures "\n" message)
  message(FATAL_ERROR "golden case ${CASE}:\n${message}")
endif()
