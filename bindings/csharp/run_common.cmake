# SPDX-License-Identifier: MIT
# What run_tests.cmake and run_mpi_tests.cmake share: the -D values they require, made absolute,
# the library folder put first on LD_LIBRARY_PATH, and sph_mcs (mcs in WORK_DIR, warnings as
# errors). Relative paths (in the -D values and in LD_LIBRARY_PATH) are taken from the folder
# cmake was started in (in -P mode, CMAKE_CURRENT_SOURCE_DIR): mcs and mono run in WORK_DIR,
# where they would not resolve.
foreach(var MCS MONO SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "${CMAKE_CURRENT_LIST_FILE}: -D${var}=... is required")
  endif()
endforeach()
foreach(var SOURCE_DIR WORK_DIR)
  get_filename_component(${var} "${${var}}" ABSOLUTE)
endforeach()
set(_library_path "")
if(DEFINED LIBRARY_DIR)
  get_filename_component(LIBRARY_DIR "${LIBRARY_DIR}" ABSOLUTE)
  list(APPEND _library_path "${LIBRARY_DIR}")
endif()
string(REPLACE ":" ";" _inherited "$ENV{LD_LIBRARY_PATH}")
foreach(dir IN LISTS _inherited)
  if(dir)
    get_filename_component(dir "${dir}" ABSOLUTE)
    list(APPEND _library_path "${dir}")
  endif()
endforeach()
string(REPLACE ";" ":" _library_path "${_library_path}")
set(ENV{LD_LIBRARY_PATH} "${_library_path}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(sph_mcs)
  execute_process(COMMAND "${MCS}" -nologo -warnaserror+ ${ARGN} WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "mcs ${ARGN} failed (${rc})")
  endif()
endfunction()
