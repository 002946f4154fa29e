# SPDX-License-Identifier: MIT
# The SIMD target objects of the CPU backend (src/cpu/cpu_simd_target_*.cpp, each built for its
# instruction set) may not share code with the rest of the library: an inline function that
# such an object defines as a global (weak) symbol could be picked by the linker for every
# caller, and then run AVX-512 code on a processor without it; a static initialiser would run
# at load time, before the dispatch has looked at the processor. So each object defines exactly
# one global symbol, its constant table kSimdPasses<Target> (and the linker's personality
# reference), and has no initialiser section.
# Usage: cmake -DOBJECTS=<objects;...> -DNM=<nm> -DOBJDUMP=<objdump> -P check_simd_objects.cmake
cmake_minimum_required(VERSION 3.24)
foreach(var OBJECTS NM OBJDUMP)
  if(NOT ${var})
    message(FATAL_ERROR "check_simd_objects.cmake: -D${var}= is required")
  endif()
endforeach()

set(checked 0)
foreach(object IN LISTS OBJECTS)
  if(NOT object MATCHES "cpu_simd_target_[a-z0-9]+\\.cpp\\.o$")
    continue()
  endif()
  math(EXPR checked "${checked} + 1")
  execute_process(COMMAND ${NM} -C --defined-only --extern-only ${object} OUTPUT_VARIABLE nm_out RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} failed on ${object}")
  endif()
  string(REPLACE "\n" ";" lines "${nm_out}")
  set(bad "")
  foreach(line IN LISTS lines)
    if(line STREQUAL "" OR line MATCHES " sph::kSimdPasses[A-Za-z0-9]+$" OR line MATCHES " DW\\.ref\\.__gxx_personality_v0$")
      continue()
    endif()
    list(APPEND bad "${line}")
  endforeach()
  if(bad)
    list(JOIN bad "\n  " bad_text)
    message(FATAL_ERROR "${object} defines global symbols besides its table (make them inline into the target's "
                        "own code, or give them internal linkage):\n  ${bad_text}")
  endif()
  execute_process(COMMAND ${OBJDUMP} -h ${object} OUTPUT_VARIABLE sections RESULT_VARIABLE rc)
  if(sections MATCHES "\\.init_array|\\.ctors")
    message(FATAL_ERROR "${object} has a static initialiser (code that would run at load time)")
  endif()
  message(STATUS "${object}: its table only, no initialiser")
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "no cpu_simd_target_*.cpp.o among the objects: the pattern is broken")
endif()
